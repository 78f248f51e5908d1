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

// The disparities searched: min .. max-1 (OpenCV's minDisparity and minDisparity +
// numDisparities). A pixel whose best match lies on the band's edge (max-1, or min when min > 0)
// is reported as kInvalidDisparity, not clamped: its cost was still falling towards a disparity
// the band leaves out, so the true match may lie beyond, and the sub-pixel fit has no neighbour
// there to say how far. (Disparity 0 is no such edge: nothing lies beyond it.)
struct DisparityRange {
    int min = 0;
    int max = 0;
    int width() const { return max - min; }
};
// The narrowest band: one disparity with a neighbour on either side for the sub-pixel fit.
inline constexpr int kMinDisparityBand = 3;

// One stereo matcher. Buffers are allocated on the first compute() for an image size and band
// width and reused for every later pair of the same size and width (a change reallocates them to
// the new size, smaller ones too) until releaseBuffers(); a matcher is not thread-safe (use one
// per thread).
class Matcher {
public:
    explicit Matcher(Method method, const Parameters& parameters = {});
    ~Matcher();
    Matcher(Matcher&&) noexcept;
    Matcher& operator=(Matcher&&) noexcept;

    // left, right: a rectified pair, same size and type: CV_8UC3 (BGR), CV_8UC1, or CV_32FC1 grey
    // levels 0..255 (the float average of several frames). Float input is matched on its rounding
    // to 8 bits, except the sub-pixel intensity refinement of the Census methods, which reads the
    // float image itself (an 8-bit image passed as float gives the same disparities bit for bit);
    // SGBM sees the rounding only. Disparities searched: range.min .. range.max-1. Returns the
    // left-view disparity, CV_32FC1, in pixels (sub-pixel), with kInvalidDisparity where there is
    // none: left of column range.min (no pixel of the right image lies in the band there) and on
    // the band's edge (DisparityRange explains). Time and memory follow the band's width. Throws
    // InvalidInput on bad input (empty, sizes or types differ, a value not finite, min < 0, fewer
    // than kMinDisparityBand disparities, max >= width).
    cv::Mat compute(const cv::Mat& left, const cv::Mat& right, DisparityRange range);
    // The band 0 .. maxDisparity-1.
    cv::Mat compute(const cv::Mat& left, const cv::Mat& right, int maxDisparity);

    // Gives back the buffers the last compute() kept (the next one allocates them again).
    void releaseBuffers();
    // Keep (the default): every buffer is kept for the next pair of the same size and band width.
    // Not keep: each stage's scratch goes back as the stage ends (the per-eye derivatives and edge
    // maps before the scanlines, where the cost volumes peak) and the rest when compute() returns.
    // For a caller that matches seldom: the chain matches one capture a cycle, minutes apart, and
    // the buffers (about 120 MB for a blade at 3840x1080) would sit idle in between, on a box of a
    // few GB, to save about 50 ms of page faults a cycle.
    void setKeepBuffers(bool keep);

    Method method() const;
    const Parameters& parameters() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// Checks a pair and a disparity range the way every method needs them; throws InvalidInput.
void validateInput(const cv::Mat& left, const cv::Mat& right, DisparityRange range);

// A float grey image (CV_32FC1) rounded to 8 bits as the integer stages see it; 8-bit images as
// they are (no copy).
cv::Mat roundedToEightBits(const cv::Mat& image);

}  // namespace icewatch::stereo
