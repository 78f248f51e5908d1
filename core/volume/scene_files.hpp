#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "core/calib/stereo_calibration.hpp"
#include "core/volume/capture_average.hpp"
#include "core/volume/chain.hpp"

namespace icewatch::volume {

// Takes one frame of a capture as it is read (side-by-side, CV_8UC3, decoded) and its name for
// messages; the frame need not outlive the call.
using FrameSink = std::function<void(const cv::Mat& frame, const std::string& name)>;

// Reads a recording directory (recording.json plus the frames exactly as the camera sent them),
// handing each decoded frame to the sink in turn: decoding camera frames is the drivers layer's,
// so the caller passes the reader. It throws Error naming the file (kExitNoInput when
// recording.json is missing, kExitDataErr for a corrupt frame).
using RecordingReader = std::function<void(const std::filesystem::path& dir, const FrameSink& sink)>;

// A scene directory as `icewatch synth` writes it (and as a person can assemble one from a real
// camera): calibration.yaml, the clean capture and the current one, and optionally roi.json. A
// capture is either one side-by-side frame (before.png, after.png) or a recording of many frames
// (before/, after/), averaged frame by frame as it is read (capture_average.hpp), so a long
// recording is never held whole. truth.json is never read here.
struct SceneFiles {
    calib::StereoCalibration calibration;
    AveragedCapture before, after;  // each with a frame, unless `unusable` says why not
    std::optional<std::vector<cv::Point2d>> roi;
    // Why a capture was read but had too few usable frames (dark, blurred, moving: the frames'
    // health and stillness checks), naming it; empty when both have a frame. A scene the camera
    // could not see well is a measurement to refuse, not malformed input.
    std::string unusable;
};

// Throws Error naming the file: kExitNoInput when one is missing, kExitDataErr when its content
// does not fit (unreadable image, frame size not twice the calibration's eye, captures of
// different sizes). A recording needs `readRecording` (kExitUsage without it).
SceneFiles loadSceneDirectory(const std::filesystem::path& dir, const RecordingReader& readRecording = {},
                              const CaptureAverageOptions& averaging = {});

}  // namespace icewatch::volume
