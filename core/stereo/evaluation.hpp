#pragma once

#include <cstdint>
#include <string>

#include <opencv2/core.hpp>

namespace icewatch::stereo {

// Middlebury v2 metric: among pixels where the mask is 255 and the ground truth is known (> 0),
// the share whose |d - gt / gtScale| > threshold; a pixel without a disparity counts as bad.
struct DisparityScore {
    double badPercent = 0.0;
    double validPercent = 0.0;  // pixels of the whole image that have a disparity
    int evaluated = 0;          // pixels counted by the metric
};
// disparity CV_32FC1 (kInvalidDisparity = none); gt and mask CV_8UC1 (empty mask: every pixel).
DisparityScore scoreDisparity(const cv::Mat& disparity, const cv::Mat& gt, double gtScale, const cv::Mat& mask,
                              double threshold);

// Image noise for robustness sweeps. "none", "saltpepper:P" (P % of the pixels, half black, half
// white) or "gauss:SIGMA" (grey levels). Throws InvalidInput naming a bad specification.
struct NoiseSpec {
    enum class Kind { None, SaltPepper, Gaussian } kind = Kind::None;
    double amount = 0.0;
    std::string text = "none";
};
NoiseSpec parseNoise(const std::string& text);
// Adds noise in place, reproducibly from seed (each image should get its own seed).
void addNoise(cv::Mat& image, const NoiseSpec& noise, std::uint64_t seed);

}  // namespace icewatch::stereo
