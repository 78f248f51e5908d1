#pragma once

#include <opencv2/core.hpp>

namespace icewatch::volume {

// The connected parts of `mask` (CV_8U) that hold at least one pixel of `seeds` (CV_8U, same
// size), whole: a morphological reconstruction. connectivity 4 or 8.
cv::Mat partsHolding(const cv::Mat& mask, const cv::Mat& seeds, int connectivity = 8);

// The 8-connected parts of `mask` (CV_8U) holding at least 1/`ofLargest` of the largest one's
// pixels, whole: what is left of an object once its background is taken out, without the specks a
// flood went round. Empty (all zero) when `mask` is.
cv::Mat largeParts(const cv::Mat& mask, int ofLargest);

// The mean of `values` (CV_32F, finite wherever `where` is set) over the pixels of `where` (CV_8U)
// within a (2r+1)² window around each pixel; NaN where the window holds none.
cv::Mat localMean(const cv::Mat& values, const cv::Mat& where, int r);

// What the region's stages keep of an outline once a background is taken out of it
// (drawn_outline, raised_object): a part smaller than 1/this of the largest is a speck the flood
// went round.
inline constexpr int kSpeckShareOfLargest = 50;

}  // namespace icewatch::volume
