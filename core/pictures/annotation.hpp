#pragma once

#include <string>

#include <opencv2/core.hpp>

namespace icewatch::pictures {

// The region's outline (CV_8U, non-zero inside) drawn on a CV_8UC3 picture of the same size.
void drawOutline(cv::Mat& picture, const cv::Mat& region);

// Writes `text` in white on a dark band across the top of a CV_8UC3 picture, wrapped to its width.
// Returns the band.
cv::Rect writeBanner(cv::Mat& picture, const std::string& text);

// The size of text on pictures of this height: legible on a 1280x720 eye and on a small test image.
double fontScaleFor(int imageRows);

}  // namespace icewatch::pictures
