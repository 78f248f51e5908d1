#pragma once

#include <chrono>
#include <functional>
#include <string>

#include <nlohmann/json.hpp>

#include "core/config/config.hpp"
#include "drivers/v4l2/camera_capture.hpp"

// What the camera subcommands (info, record, acquire) share.
namespace icewatch::cli {

// The camera section of configFile (or the defaults without one), with --device on top.
config::CameraConfig cameraConfig(const std::string& configFile, const std::string& device);

// "2560x720" -> width, height; throws Error (64) naming the argument otherwise.
void parseMode(const std::string& text, int& width, int& height);

nlohmann::json modeJson(const v4l2::NegotiatedMode& mode);
nlohmann::json droppedJson(const v4l2::CaptureStats& stats);

// Calls step until it returns kNone `frames` times or timeoutS passes. Offline errors are
// retried (the capture backs off by itself); configuration errors end at once. Returns the
// last error when it gave up, kNone when all frames came.
v4l2::CaptureError collectFrames(int frames, double timeoutS, const std::function<v4l2::CaptureError()>& step);

// Throws Error with the capture's exit status and message.
[[noreturn]] void throwCaptureError(v4l2::CaptureError error, const v4l2::CameraCapture& capture);

}  // namespace icewatch::cli
