#pragma once

#include <filesystem>
#include <functional>
#include <string>

#include <opencv2/core.hpp>

#include "core/common/side_by_side.hpp"

namespace icewatch::cli {

// Reads an image as 8-bit BGR. Throws Error naming the file: kExitNoInput when it is missing,
// kExitDataErr when it cannot be decoded.
cv::Mat readImage(const std::filesystem::path& path);

// Calls visit(name, pair) for every stereo pair of a calibration session, in order, loading one
// pair at a time. `source` is either
//  - a directory of side-by-side frames: a recording written by `icewatch record` (recording.json
//    beside 000001.jpg ...; raw .yuyv frames are decoded with the width and height recorded in
//    recording.json) or any directory of side-by-side .jpg/.jpeg/.png images, taken in name
//    order and split into halves (left eye = left half); or
//  - an OpenCV image-list file (.xml/.yaml/.yml, as OpenCV's stereo_calib sample reads): left and
//    right image names alternating, relative to the list's folder unless absolute.
// `step` keeps every step-th pair (a recording at 30 fps holds many near-identical frames).
// Throws Error naming the file: kExitNoInput for a missing source or image, kExitDataErr for an
// unreadable image, an odd-length list or a frame that cannot be split.
using PairVisitor = std::function<void(const std::string& name, const StereoPair& pair)>;
void forEachCalibrationPair(const std::filesystem::path& source, int step, const PairVisitor& visit);

}  // namespace icewatch::cli
