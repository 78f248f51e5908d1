#pragma once

#include <memory>
#include <string>
#include <string_view>

#include <opencv2/core.hpp>

#include "core/stereo/parameters.hpp"

namespace icewatch::stereo {

// Disparity value of a pixel that has none (occluded, unmatched, outside the search range).
inline constexpr float kInvalidDisparity = -1.0f;

enum class Method {
    Paper,     // Wei et al. 2025: improved Census + AD + gradient, cross aggregation, 8-way scanlines
    AdCensus,  // Mei et al. 2011, the paper's baseline
    Sgbm,      // OpenCV StereoSGBM, 3-way mode (wrapped, not rewritten)
};

// "paper", "adcensus", "sgbm"; parseMethod throws InvalidInput naming the bad value.
Method parseMethod(std::string_view name);
std::string methodName(Method method);

// One stereo matcher. Buffers are allocated on the first compute() for an image size and reused
// for every later pair of the same size; a matcher is not thread-safe (use one per thread).
class Matcher {
public:
    explicit Matcher(Method method, const Parameters& parameters = {});
    ~Matcher();
    Matcher(Matcher&&) noexcept;
    Matcher& operator=(Matcher&&) noexcept;

    // left, right: a rectified pair, same size, CV_8UC3 (BGR) or CV_8UC1. Disparities searched:
    // 0 .. maxDisparity-1. Returns the left-view disparity, CV_32FC1, in pixels (sub-pixel), with
    // kInvalidDisparity where there is none. Throws InvalidInput on bad input (empty, sizes or
    // types differ, maxDisparity <= 0 or >= width).
    cv::Mat compute(const cv::Mat& left, const cv::Mat& right, int maxDisparity);

    Method method() const;
    const Parameters& parameters() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// Checks a pair and a disparity range the way every method needs them; throws InvalidInput.
void validateInput(const cv::Mat& left, const cv::Mat& right, int maxDisparity);

}  // namespace icewatch::stereo
