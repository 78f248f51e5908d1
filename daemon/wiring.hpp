#pragma once

#include <memory>
#include <optional>
#include <string>

#include "core/config/config.hpp"
#include "daemon/frame_source.hpp"
#include "daemon/measurement_chain.hpp"
#include "drivers/gpio/scada_outputs.hpp"

namespace icewatch::daemon {

// The production parts for a configuration: the capture for camera.device (a V4L2 node, or
// fake:DIR replaying a recording through the fake V4L2 device), the volume chain with the
// calibration calibration.file and the alarm outputs of gpio. The last two throw Error with what
// to do ("no calibration: run icewatch calibrate ...", "no GPIO chip gpiochip0 ...") for the
// daemon to report and retry (DaemonParts).
std::unique_ptr<FrameSource> makeFrameSource(const config::Config& config);
std::unique_ptr<MeasurementChain> makeMeasurementChain(const config::Config& config);
std::unique_ptr<gpio::ScadaOutputs> openAlarmOutputs(const config::GpioConfig& config);
// "no GPIO chip gpiochip0 (...)" when gpio.chip names a device that does not exist, else nullopt.
std::optional<std::string> missingGpioChip(const config::GpioConfig& config);

}  // namespace icewatch::daemon
