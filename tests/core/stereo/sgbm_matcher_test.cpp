#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "core/common/error.hpp"
#include "core/stereo/matcher.hpp"
#include "core/stereo/sgbm_matcher.hpp"

namespace icewatch::stereo {
namespace {

TEST(Matcher, MethodNames) {
    EXPECT_EQ(parseMethod("sgbm"), Method::Sgbm);
    EXPECT_EQ(methodName(parseMethod("paper")), "paper");
    EXPECT_THROW(parseMethod("bm"), InvalidInput);
}

TEST(Matcher, SgbmFindsAConstantShift) {
    // A random texture shifted by 7 px: SGBM must find 7 nearly everywhere it can see.
    cv::Mat right(60, 120, CV_8UC3);
    cv::randu(right, 0, 255);
    cv::GaussianBlur(right, right, {3, 3}, 0.8);
    cv::Mat left(right.size(), right.type(), cv::Scalar::all(0));
    right(cv::Rect(0, 0, 113, 60)).copyTo(left(cv::Rect(7, 0, 113, 60)));
    Matcher matcher(Method::Sgbm);
    const cv::Mat d = matcher.compute(left, right, 16);
    ASSERT_EQ(d.type(), CV_32FC1);
    int good = 0, total = 0;
    for (int y = 5; y < 55; ++y)
        for (int x = 30; x < 110; ++x) {
            ++total;
            good += std::abs(d.at<float>(y, x) - 7.0f) <= 0.5f;
        }
    EXPECT_GT(good, total * 95 / 100);
}

TEST(Matcher, RejectsBadInput) {
    Matcher matcher(Method::Sgbm);
    const cv::Mat a(10, 20, CV_8UC3, cv::Scalar::all(1));
    EXPECT_THROW(matcher.compute(cv::Mat(), a, 4), InvalidInput);
    EXPECT_THROW(matcher.compute(a, cv::Mat(10, 21, CV_8UC3), 4), InvalidInput);
    EXPECT_THROW(matcher.compute(a, cv::Mat(10, 20, CV_32FC3), 4), InvalidInput);
    EXPECT_THROW(matcher.compute(a, a, 0), InvalidInput);
    EXPECT_THROW(matcher.compute(a, a, 20), InvalidInput);
}

TEST(FillHoles, TakesTheBackgroundSide) {
    cv::Mat d = (cv::Mat_<float>(1, 6) << 5, -1, -1, 9, -1, -1);
    fillHolesAlongRows(d);
    EXPECT_EQ(d.at<float>(0, 1), 5.0f);
    EXPECT_EQ(d.at<float>(0, 2), 5.0f);
    EXPECT_EQ(d.at<float>(0, 4), 9.0f);
    EXPECT_EQ(d.at<float>(0, 5), 9.0f);
}

}  // namespace
}  // namespace icewatch::stereo
