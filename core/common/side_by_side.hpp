#pragma once

#include <opencv2/core.hpp>

namespace icewatch {

// One stereo pair, left and right eye, same size and type.
struct StereoPair {
    cv::Mat left;
    cv::Mat right;
};

// Splits a side-by-side frame as the HBVCAM delivers it: left eye = left half. The halves are
// deep copies, so the frame buffer can be reused at once. Throws InvalidInput on an empty frame or
// an odd width (a frame that cannot be two equal eyes is not from this camera).
StereoPair splitSideBySide(const cv::Mat& frame);
// The same halves as views into the frame, no copy: for a caller that is done with them before the
// frame changes (the volume chain rectifies them at once; copies are 17 MB at 3840x1080 in float).
StereoPair sideBySideViews(const cv::Mat& frame);

// The inverse: puts two equal-sized eyes next to each other (recordings, synthetic scenes).
cv::Mat joinSideBySide(const cv::Mat& left, const cv::Mat& right);

}  // namespace icewatch
