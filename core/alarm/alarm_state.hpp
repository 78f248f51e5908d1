#pragma once

#include <chrono>
#include <optional>
#include <string>

#include "core/config/config.hpp"

namespace icewatch::alarm {

// What SCADA is told. Fault means "cannot tell": it is never shown as no ice.
enum class AlarmLevel { None, Warning, Alarm, Fault };

const char* toString(AlarmLevel level);

using TimePoint = std::chrono::system_clock::time_point;

// One accepted measurement: both metrics, each with its expanded uncertainty (coverage k = 2).
struct Reading {
    double volumeMm3 = 0.0;
    double volumeUncertaintyMm3 = 0.0;
    double meanThicknessMm = 0.0;
    double meanThicknessUncertaintyMm = 0.0;
};

// The value the levels follow: the configured metric, plus its uncertainty when judge is
// upper_bound.
double judgedValue(const config::AlarmConfig& config, const Reading& reading);

// The alarm state machine. Time is always passed in (core reads no clock).
//
// - Levels none < warning < alarm follow one metric (volume or mean thickness) with separate set
//   and clear thresholds: a level is entered at its set threshold and left only at or below its
//   clear threshold. With judge upper_bound the metric's uncertainty is added first: a reading of
//   -65 000 ± 340 000 mm3 says only that up to 275 000 mm3 may be there.
// - Raising is immediate; lowering waits until the current level has been held for its minimum
//   hold time.
// - With latch on, an alarm stays until reset(), which re-judges the last value at once.
// - fault() (camera, measurement failure, no baseline) shows Fault until the next accepted
//   measurement; the ice level and its timers survive the fault.
// - Refused measurements (the quality gate) do not reach this class at all.
// It starts in Fault ("no measurement yet"): until something was measured nothing is known.
class AlarmStateMachine {
public:
    explicit AlarmStateMachine(const config::AlarmConfig& config);

    // New thresholds take effect with the next measurement; the state is kept.
    void setConfig(const config::AlarmConfig& config);

    AlarmLevel measured(const Reading& reading, TimePoint now);
    // A reading known exactly (tests of the levels themselves).
    AlarmLevel measured(double volumeMm3, double meanThicknessMm, TimePoint now) {
        return measured(Reading{volumeMm3, 0.0, meanThicknessMm, 0.0}, now);
    }
    AlarmLevel fault(const std::string& reason);
    AlarmLevel reset(TimePoint now);

    AlarmLevel level() const { return faulted_ ? AlarmLevel::Fault : iceLevel_; }
    AlarmLevel iceLevel() const { return iceLevel_; }
    bool faulted() const { return faulted_; }
    const std::string& faultReason() const { return faultReason_; }
    bool latched() const { return config_.latch && iceLevel_ == AlarmLevel::Alarm; }

private:
    AlarmLevel target(double value) const;
    int holdS(AlarmLevel level) const;
    void enter(AlarmLevel level, TimePoint now);

    config::AlarmConfig config_;
    AlarmLevel iceLevel_ = AlarmLevel::None;
    TimePoint enteredAt_{};
    std::optional<Reading> lastReading_;  // judged again under the config of the moment
    bool faulted_ = true;
    std::string faultReason_ = "no measurement yet";
};

}  // namespace icewatch::alarm
