#pragma once

#include <filesystem>
#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "core/calib/stereo_calibration.hpp"
#include "core/volume/chain.hpp"

namespace icewatch::volume {

// A scene directory as `icewatch synth` writes it (and as a person can assemble one from a real
// camera): calibration.yaml, before.png, after.png (side-by-side frames) and optionally roi.json.
// truth.json is never read here.
struct SceneFiles {
    calib::StereoCalibration calibration;
    cv::Mat before, after;
    std::optional<std::vector<cv::Point2d>> roi;
};

// Throws Error naming the file: kExitNoInput when one is missing, kExitDataErr when its content
// does not fit (unreadable image, frame size not twice the calibration's eye, captures of
// different sizes).
SceneFiles loadSceneDirectory(const std::filesystem::path& dir);

// Writes disparity.png (false colour), thickness.png and cloud.ply (current surface in the
// baseline's frame, coloured by thickness). Throws Error(kExitCantCreate).
void writeDebugOutput(const VolumeResult& result, const std::filesystem::path& dir);

}  // namespace icewatch::volume
