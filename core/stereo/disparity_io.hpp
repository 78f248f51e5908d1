#pragma once

#include <filesystem>

#include <opencv2/core.hpp>

namespace icewatch::stereo {

// Portable Float Map ("Pf", one channel, little endian, rows bottom to top), the Middlebury
// format for disparities. Invalid pixels are written as +infinity, as Middlebury does, and read
// back as kInvalidDisparity. Errors throw icewatch::Error naming the file (exit 73 can't create,
// 74 I/O, 65 malformed, 66 missing).
void writePfm(const std::filesystem::path& path, const cv::Mat& disparity);
cv::Mat readPfm(const std::filesystem::path& path);

// False colour for people on the scale 0 .. maxDisparity (core/pictures' colour map): near (large
// disparity) warm, far cold, invalid black. CV_8UC3, no colour bar.
cv::Mat colorizeDisparity(const cv::Mat& disparity, int maxDisparity);

}  // namespace icewatch::stereo
