#pragma once

#include <memory>

#include "core/config/config.hpp"
#include "daemon/frame_source.hpp"
#include "drivers/v4l2/camera_capture.hpp"
#include "drivers/v4l2/device_seam.hpp"

namespace icewatch::daemon {

// FrameSource over the V4L2 capture: a real camera, or fake:DIR replaying a recording through the
// fake uvcvideo device (the real driver code runs on top of it either way).
class V4l2FrameSource : public FrameSource {
public:
    // Throws Error when a fake:DIR recording cannot be read.
    explicit V4l2FrameSource(const config::CameraConfig& config, const v4l2::FakeUvcOptions& fakeOptions = {},
                             v4l2::CaptureOptions captureOptions = {});

    bool open(std::string& error) override;
    std::optional<StereoPair> grabFreshest(std::string& error) override;
    // Grabs a frame to see that the camera is alive (a vanished camera is only noticed by using
    // it); re-opens one that went away. Degraded: frames were dropped since the last look, or the
    // driver substituted the configured mode.
    CameraState health(std::string& detail) override;
    void close() override;

private:
    std::string describe(v4l2::CaptureError error) const;

    v4l2::DeviceSeam seam_;
    std::unique_ptr<v4l2::CameraCapture> capture_;
    std::uint64_t droppedAtLastLook_ = 0;
};

}  // namespace icewatch::daemon
