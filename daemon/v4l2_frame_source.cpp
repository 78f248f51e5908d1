// The daemon's frames from the V4L2 capture. The capture reconnects with back-off on its own; this
// adapter turns its error enum into the daemon's camera states and readable reasons.
#include "daemon/v4l2_frame_source.hpp"

namespace icewatch::daemon {

namespace {
// Frames that arrive but are all dropped (corrupt JPEG, error flags): a few attempts, then give up.
constexpr int kAttemptsPerFrame = 3;
}  // namespace

V4l2FrameSource::V4l2FrameSource(const config::CameraConfig& config, const v4l2::FakeUvcOptions& fakeOptions,
                                 v4l2::CaptureOptions captureOptions)
    : seam_(v4l2::makeDeviceSeam(config.device, fakeOptions)),
      capture_(std::make_unique<v4l2::CameraCapture>(config, *seam_.syscalls, seam_.path, std::move(captureOptions))) {}

std::string V4l2FrameSource::describe(v4l2::CaptureError error) const {
    const std::string detail = capture_->lastError();
    return std::string(v4l2::captureErrorName(error)) + (detail.empty() ? "" : ": " + detail);
}

bool V4l2FrameSource::open(std::string& error) {
    if (capture_->isStreaming()) {
        return true;
    }
    const v4l2::CaptureError e = capture_->start();
    if (e != v4l2::CaptureError::kNone) {
        error = describe(e);
        return false;
    }
    return true;
}

std::optional<StereoPair> V4l2FrameSource::grabFreshest(std::string& error) {
    v4l2::CapturedFrame frame;
    v4l2::CaptureError e = v4l2::CaptureError::kNoValidFrame;
    for (int attempt = 0; attempt < kAttemptsPerFrame && e == v4l2::CaptureError::kNoValidFrame; ++attempt) {
        e = capture_->grab(frame);
    }
    if (e != v4l2::CaptureError::kNone) {
        error = describe(e);
        return std::nullopt;
    }
    return std::move(frame.pair);
}

CameraState V4l2FrameSource::health(std::string& detail) {
    std::string error;
    if (!open(error)) {
        detail = error;
        return CameraState::Offline;
    }
    if (!grabFreshest(error)) {
        detail = error;
        return CameraState::Offline;
    }
    const std::uint64_t dropped = capture_->stats().droppedTotal();
    const bool dropping = dropped != droppedAtLastLook_;
    droppedAtLastLook_ = dropped;
    if (dropping || capture_->mode().substituted) {
        detail = dropping ? "dropping frames (" + std::to_string(dropped) + " so far)" : "the driver substituted the mode";
        return CameraState::Degraded;
    }
    detail.clear();
    return CameraState::Ok;
}

void V4l2FrameSource::close() {
    capture_->stop();
}

}  // namespace icewatch::daemon
