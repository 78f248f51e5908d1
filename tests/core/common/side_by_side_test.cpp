#include "core/common/side_by_side.hpp"

#include <gtest/gtest.h>

#include "core/common/error.hpp"

namespace icewatch {
namespace {

TEST(SideBySide, LeftEyeIsLeftHalf) {
    cv::Mat frame(3, 8, CV_8UC3);
    for (int y = 0; y < frame.rows; ++y)
        for (int x = 0; x < frame.cols; ++x) frame.at<cv::Vec3b>(y, x) = cv::Vec3b(uchar(x), uchar(y), uchar(x + y));
    const StereoPair pair = splitSideBySide(frame);
    ASSERT_EQ(pair.left.size(), cv::Size(4, 3));
    ASSERT_EQ(pair.right.size(), cv::Size(4, 3));
    EXPECT_EQ(pair.left.at<cv::Vec3b>(2, 3), cv::Vec3b(3, 2, 5));
    EXPECT_EQ(pair.right.at<cv::Vec3b>(1, 0), cv::Vec3b(4, 1, 5));
    // Deep copies: the capture buffer may be reused at once.
    frame.setTo(cv::Scalar::all(0));
    EXPECT_EQ(pair.right.at<cv::Vec3b>(1, 0), cv::Vec3b(4, 1, 5));
}

TEST(SideBySide, ViewsShareTheFrame) {
    cv::Mat frame(4, 6, CV_32FC1);
    cv::randu(frame, 0, 255);
    const StereoPair views = sideBySideViews(frame);
    const StereoPair copies = splitSideBySide(frame);
    EXPECT_EQ(cv::norm(views.left, copies.left, cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(views.right, copies.right, cv::NORM_INF), 0.0);
    frame.at<float>(1, 4) = -7.0f;  // right eye (1, 1)
    EXPECT_EQ(views.right.at<float>(1, 1), -7.0f);
    EXPECT_THROW(sideBySideViews(cv::Mat(2, 7, CV_8UC3)), InvalidInput);
}

TEST(SideBySide, JoinIsTheInverse) {
    cv::Mat frame(5, 10, CV_8UC1);
    cv::randu(frame, 0, 255);
    const StereoPair pair = splitSideBySide(frame);
    EXPECT_EQ(cv::norm(joinSideBySide(pair.left, pair.right), frame, cv::NORM_INF), 0.0);
}

TEST(SideBySide, RejectsEmptyAndOddFrames) {
    EXPECT_THROW(splitSideBySide(cv::Mat()), InvalidInput);
    EXPECT_THROW(splitSideBySide(cv::Mat(2, 7, CV_8UC3)), InvalidInput);
    EXPECT_THROW(joinSideBySide(cv::Mat(2, 2, CV_8UC1), cv::Mat(2, 3, CV_8UC1)), InvalidInput);
}

}  // namespace
}  // namespace icewatch
