// Fail-safe signalling: every healthy, no-alarm state is an energised line, so anything that
// takes the power away (a crash, a pulled cable, a dead box) reads as fault and alarm on the SCADA
// side. The healthy line is dropped first and raised last, so SCADA never reads "healthy" beside
// an alarm line that is still changing.
#include "drivers/gpio/scada_outputs.hpp"

#include "drivers/gpio/gpiod_output_line.hpp"
#include "drivers/log/log.hpp"

namespace icewatch::gpio {

ScadaOutputs::ScadaOutputs(std::unique_ptr<OutputLine> alarmLine, std::unique_ptr<OutputLine> healthyLine)
    : alarmLine_(std::move(alarmLine)), healthyLine_(std::move(healthyLine)) {}

ScadaOutputs::~ScadaOutputs() {
    failSafe();
}

bool ScadaOutputs::drive(bool alarmEnergised, bool healthyEnergised) {
    bool ok = true;
    if (healthyLine_ && !healthyEnergised) ok = healthyLine_->set(false) && ok;
    if (alarmLine_) ok = alarmLine_->set(alarmEnergised) && ok;
    if (healthyLine_ && healthyEnergised) ok = healthyLine_->set(true) && ok;
    return ok;
}

bool ScadaOutputs::show(alarm::AlarmLevel level) {
    switch (level) {
        case alarm::AlarmLevel::None:
        case alarm::AlarmLevel::Warning: return drive(true, true);
        case alarm::AlarmLevel::Alarm: return drive(false, true);
        case alarm::AlarmLevel::Fault: break;
    }
    return drive(false, false);
}

bool ScadaOutputs::failSafe() {
    return drive(false, false);
}

std::unique_ptr<ScadaOutputs> openScadaOutputs(const config::GpioConfig& config, std::shared_ptr<TransitionLog> fakeLog) {
    if (config.chip == "none") {
        log::get("gpio")->warn("gpio.chip is \"none\": no alarm or healthy output is driven");
        return std::make_unique<ScadaOutputs>(nullptr, nullptr);
    }
    if (config.chip == "fake" || config.chip.rfind("fake:", 0) == 0) {
        if (!fakeLog) {
            fakeLog = config.chip == "fake" ? std::make_shared<TransitionLog>()
                                            : std::make_shared<TransitionLog>(config.chip.substr(5));
        }
        return std::make_unique<ScadaOutputs>(std::make_unique<FakeOutputLine>("alarm", fakeLog),
                                              std::make_unique<FakeOutputLine>("healthy", fakeLog));
    }
    auto alarmLine = std::make_unique<GpiodOutputLine>(config.chip, static_cast<unsigned>(config.alarmLine),
                                                       config.activeLow, config.consumer);
    auto healthyLine = std::make_unique<GpiodOutputLine>(config.chip, static_cast<unsigned>(config.healthyLine),
                                                         config.activeLow, config.consumer);
    return std::make_unique<ScadaOutputs>(std::move(alarmLine), std::move(healthyLine));
}

}  // namespace icewatch::gpio
