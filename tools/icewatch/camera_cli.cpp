// Helpers shared by the camera subcommands: configuration, argument parsing, JSON views.
#include "tools/icewatch/camera_cli.hpp"

#include <cstdio>

#include "core/common/error.hpp"

namespace icewatch::cli {

config::CameraConfig cameraConfig(const std::string& configFile, const std::string& device) {
    config::CameraConfig camera;
    if (!configFile.empty()) {
        camera = config::loadConfig(configFile).camera;
    }
    if (!device.empty()) {
        camera.device = device;
    }
    return camera;
}

void parseMode(const std::string& text, int& width, int& height) {
    int w = 0;
    int h = 0;
    char rest = 0;
    if (std::sscanf(text.c_str(), "%dx%d%c", &w, &h, &rest) != 2 || w < 2 || h < 1 || w % 2 != 0) {
        throw Error(kExitUsage, "--mode: expected WIDTHxHEIGHT with an even width, e.g. 2560x720, got \"" + text + "\"");
    }
    width = w;
    height = h;
}

nlohmann::json modeJson(const v4l2::NegotiatedMode& mode) {
    return {{"format", v4l2::formatName(mode.format)},
            {"width", mode.width},
            {"height", mode.height},
            {"fps", mode.fps},
            {"buffers", mode.buffers},
            {"substituted", mode.substituted},
            {"driver", mode.driver},
            {"card", mode.card},
            {"bus_info", mode.busInfo},
            {"controls", mode.controls}};
}

nlohmann::json droppedJson(const v4l2::CaptureStats& stats) {
    nlohmann::json dropped = {{"total", stats.droppedTotal()}};
    for (std::size_t i = 0; i < v4l2::kDropReasonCount; ++i) {
        dropped[v4l2::dropReasonName(static_cast<v4l2::DropReason>(i))] = stats.dropped[i];
    }
    return dropped;
}

v4l2::CaptureError collectFrames(int frames, double timeoutS, const std::function<v4l2::CaptureError()>& step) {
    using v4l2::CaptureError;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeoutS);
    CaptureError last = CaptureError::kNone;
    int got = 0;
    while (got < frames) {
        last = step();
        if (last == CaptureError::kNone) {
            ++got;
            continue;
        }
        if (last == CaptureError::kBadControl || last == CaptureError::kFormatUnsupported ||
            last == CaptureError::kNotCaptureDevice || last == CaptureError::kPermission) {
            return last;  // retrying cannot fix the configuration or the permissions
        }
        if (std::chrono::steady_clock::now() >= deadline) {
            return last;
        }
    }
    return CaptureError::kNone;
}

void throwCaptureError(v4l2::CaptureError error, const v4l2::CameraCapture& capture) {
    throw Error(v4l2::exitCodeFor(error),
                std::string("camera ") + v4l2::captureErrorName(error) + ": " + capture.lastError());
}

}  // namespace icewatch::cli
