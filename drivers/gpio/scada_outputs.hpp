#pragma once

#include <memory>

#include "core/alarm/alarm_state.hpp"
#include "core/config/config.hpp"
#include "drivers/gpio/fake_output_line.hpp"
#include "drivers/gpio/output_line.hpp"

namespace icewatch::gpio {

// The two lines toward SCADA and the fail-safe mapping of the alarm level onto them:
//   none, warning   alarm line energised,    healthy line energised
//   alarm           alarm line de-energised, healthy line energised
//   fault           alarm line de-energised, healthy line de-energised (= a crash or power loss)
// Warning is not wired out (two lines); it is in latest.json and the HTTP API.
class ScadaOutputs {
public:
    // Either line may be null (gpio.chip "none"): nothing is driven then.
    ScadaOutputs(std::unique_ptr<OutputLine> alarmLine, std::unique_ptr<OutputLine> healthyLine);
    // Leaves both lines de-energised.
    ~ScadaOutputs();
    ScadaOutputs(const ScadaOutputs&) = delete;
    ScadaOutputs& operator=(const ScadaOutputs&) = delete;

    // Returns false when a line could not be driven.
    bool show(alarm::AlarmLevel level);
    // Both de-energised: what SCADA sees on shutdown.
    bool failSafe();

private:
    bool drive(bool alarmEnergised, bool healthyEnergised);

    std::unique_ptr<OutputLine> alarmLine_;
    std::unique_ptr<OutputLine> healthyLine_;
};

// Opens the lines the configuration names: a gpiochip through libgpiod, "none", "fake" (recorded
// in fakeLog, created when null) or fake:FILE (also appended to FILE). Throws Error
// (kExitUnavailable) when a real chip or line cannot be had.
std::unique_ptr<ScadaOutputs> openScadaOutputs(const config::GpioConfig& config,
                                               std::shared_ptr<TransitionLog> fakeLog = nullptr);

}  // namespace icewatch::gpio
