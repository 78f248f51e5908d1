#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "core/calib/stereo_calibration.hpp"
#include "core/volume/chain.hpp"

namespace icewatch::volume {

// The frames of one capture, as read from a scene directory, and their names for messages.
struct CaptureFiles {
    std::vector<cv::Mat> frames;  // side-by-side, CV_8UC3, as the camera delivered them (decoded)
    std::vector<std::string> names;
};

// Reads a recording directory (recording.json plus the frames exactly as the camera sent them):
// decoding camera frames is the drivers layer's, so the caller passes the reader. It throws Error
// naming the file (kExitNoInput when recording.json is missing, kExitDataErr for a corrupt frame).
using RecordingReader = std::function<CaptureFiles(const std::filesystem::path& dir)>;

// A scene directory as `icewatch synth` writes it (and as a person can assemble one from a real
// camera): calibration.yaml, the clean capture and the current one, and optionally roi.json. A
// capture is either one side-by-side frame (before.png, after.png) or a recording of many frames
// (before/, after/), to be averaged. truth.json is never read here.
struct SceneFiles {
    calib::StereoCalibration calibration;
    CaptureFiles before, after;
    std::optional<std::vector<cv::Point2d>> roi;
};

// Throws Error naming the file: kExitNoInput when one is missing, kExitDataErr when its content
// does not fit (unreadable image, frame size not twice the calibration's eye, captures of
// different sizes). A recording needs `readRecording` (kExitUsage without it).
SceneFiles loadSceneDirectory(const std::filesystem::path& dir, const RecordingReader& readRecording = {});

}  // namespace icewatch::volume
