#pragma once

#include <memory>

#include "core/config/config.hpp"
#include "daemon/frame_source.hpp"
#include "daemon/measurement_chain.hpp"

namespace icewatch::daemon {

// The production parts for a configuration: the capture for camera.device (a V4L2 node, or
// fake:DIR replaying a recording through the fake V4L2 device) and the volume chain with the
// calibration calibration.file.
std::unique_ptr<FrameSource> makeFrameSource(const config::Config& config);
std::unique_ptr<MeasurementChain> makeMeasurementChain(const config::Config& config);

}  // namespace icewatch::daemon
