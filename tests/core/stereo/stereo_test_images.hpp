#pragma once
// Shared helpers of the stereo tests: reproducible random images at awkward sizes.

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace icewatch::stereo::test {

// Smoothed noise: textured enough for Census, smooth enough for long cross arms.
inline cv::Mat randomImage(int width, int height, int type, std::uint64_t seed) {
    cv::RNG rng(seed);
    cv::Mat image(height, width, type);
    rng.fill(image, cv::RNG::UNIFORM, 0, 256);
    cv::GaussianBlur(image, image, {5, 5}, 1.2);
    return image;
}

}  // namespace icewatch::stereo::test
