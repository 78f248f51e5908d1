#pragma once

#include <opencv2/core.hpp>

namespace icewatch::volume {

// The connected parts of `mask` (CV_8U) that hold at least one pixel of `seeds` (CV_8U, same
// size), whole: a morphological reconstruction. connectivity 4 or 8.
cv::Mat partsHolding(const cv::Mat& mask, const cv::Mat& seeds, int connectivity = 8);

}  // namespace icewatch::volume
