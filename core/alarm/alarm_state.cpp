// The ice alarm toward SCADA. Hysteresis keeps a value hovering at a threshold from toggling the
// relay every cycle; minimum hold times keep one noisy low measurement from clearing a real alarm;
// latching lets an operator insist on seeing an alarm before it goes. A fault is its own level so
// that "cannot see the blade" is never mistaken for "no ice".
#include "core/alarm/alarm_state.hpp"

namespace icewatch::alarm {

const char* toString(AlarmLevel level) {
    switch (level) {
        case AlarmLevel::None: return "none";
        case AlarmLevel::Warning: return "warning";
        case AlarmLevel::Alarm: return "alarm";
        case AlarmLevel::Fault: return "fault";
    }
    return "fault";
}

double judgedValue(const config::AlarmConfig& config, const Reading& reading) {
    const bool thickness = config.metric == "mean_thickness_mm";
    const double value = thickness ? reading.meanThicknessMm : reading.volumeMm3;
    if (config.judge != "upper_bound") {
        return value;
    }
    return value + (thickness ? reading.meanThicknessUncertaintyMm : reading.volumeUncertaintyMm3);
}

AlarmStateMachine::AlarmStateMachine(const config::AlarmConfig& config) : config_(config) {}

void AlarmStateMachine::setConfig(const config::AlarmConfig& config) {
    config_ = config;
}

AlarmLevel AlarmStateMachine::target(double value) const {
    if (value >= config_.alarmSet || (iceLevel_ == AlarmLevel::Alarm && value > config_.alarmClear)) {
        return AlarmLevel::Alarm;
    }
    if (value >= config_.warningSet || (iceLevel_ != AlarmLevel::None && value > config_.warningClear)) {
        return AlarmLevel::Warning;
    }
    return AlarmLevel::None;
}

int AlarmStateMachine::holdS(AlarmLevel level) const {
    return level == AlarmLevel::Alarm ? config_.alarmHoldS : level == AlarmLevel::Warning ? config_.warningHoldS : 0;
}

void AlarmStateMachine::enter(AlarmLevel level, TimePoint now) {
    if (level != iceLevel_) {
        iceLevel_ = level;
        enteredAt_ = now;
    }
}

AlarmLevel AlarmStateMachine::measured(const Reading& reading, TimePoint now) {
    const double value = judgedValue(config_, reading);
    const bool first = !lastReading_.has_value();
    lastReading_ = reading;
    faulted_ = false;
    faultReason_.clear();
    const AlarmLevel wanted = target(value);
    if (first || wanted > iceLevel_) {
        enter(wanted, now);
    } else if (wanted < iceLevel_) {
        const bool held = now - enteredAt_ >= std::chrono::seconds(holdS(iceLevel_));
        if (held && !latched()) {
            enter(wanted, now);
        }
    }
    return level();
}

AlarmLevel AlarmStateMachine::fault(const std::string& reason) {
    faulted_ = true;
    faultReason_ = reason;
    return level();
}

AlarmLevel AlarmStateMachine::reset(TimePoint now) {
    // An operator's reset releases the latch and the hold, not the physics: ice still above the
    // clear threshold keeps its level.
    if (lastReading_) {
        enter(target(judgedValue(config_, *lastReading_)), now);
    }
    return level();
}

}  // namespace icewatch::alarm
