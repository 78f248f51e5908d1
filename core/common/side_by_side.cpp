#include "core/common/side_by_side.hpp"

#include <string>

#include "core/common/error.hpp"

namespace icewatch {

StereoPair splitSideBySide(const cv::Mat& frame) {
    const StereoPair views = sideBySideViews(frame);
    return {views.left.clone(), views.right.clone()};
}

StereoPair sideBySideViews(const cv::Mat& frame) {
    if (frame.empty()) {
        throw InvalidInput("side-by-side frame is empty");
    }
    if (frame.cols % 2 != 0) {
        throw InvalidInput("side-by-side frame width " + std::to_string(frame.cols) +
                           " is odd: it cannot hold two equal eyes");
    }
    const int eyeWidth = frame.cols / 2;
    StereoPair pair;
    pair.left = frame(cv::Rect(0, 0, eyeWidth, frame.rows));
    pair.right = frame(cv::Rect(eyeWidth, 0, eyeWidth, frame.rows));
    return pair;
}

cv::Mat joinSideBySide(const cv::Mat& left, const cv::Mat& right) {
    if (left.empty() || right.empty()) {
        throw InvalidInput("cannot join an empty eye into a side-by-side frame");
    }
    if (left.size() != right.size() || left.type() != right.type()) {
        throw InvalidInput("left and right eyes differ in size or type");
    }
    cv::Mat frame;
    cv::hconcat(left, right, frame);
    return frame;
}

}  // namespace icewatch
