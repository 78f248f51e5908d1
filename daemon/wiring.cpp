// Chooses the production implementations of the daemon's two seams: the V4L2 capture (or the
// fake uvcvideo device for fake:DIR) and the volume chain with the configured calibration.
#include "daemon/wiring.hpp"

#include "daemon/v4l2_frame_source.hpp"
#include "daemon/volume_measurement_chain.hpp"

namespace icewatch::daemon {

std::unique_ptr<FrameSource> makeFrameSource(const config::Config& config) {
    return std::make_unique<V4l2FrameSource>(config.camera);
}

std::unique_ptr<MeasurementChain> makeMeasurementChain(const config::Config& config) {
    return std::make_unique<VolumeMeasurementChain>(config.calibration.file, config.volume,
                                                    config.pictures);
}

}  // namespace icewatch::daemon
