// Connected parts of a mask (mask_parts.hpp).
#include <gtest/gtest.h>

#include "core/volume/mask_parts.hpp"

namespace icewatch::volume {
namespace {

// Two parts touching only at a corner are one under 8-connectivity, two under 4; a seed keeps its
// whole part and nothing else.
TEST(MaskParts, ASeedKeepsItsWholePartAndNoOther) {
    cv::Mat mask = cv::Mat::zeros(20, 20, CV_8U);
    mask(cv::Rect(2, 2, 4, 4)).setTo(255);    // part A
    mask(cv::Rect(6, 6, 3, 3)).setTo(255);    // part B, touching A at a corner
    mask(cv::Rect(12, 12, 5, 2)).setTo(255);  // part C
    cv::Mat seeds = cv::Mat::zeros(20, 20, CV_8U);
    seeds.at<std::uint8_t>(3, 3) = 255;  // in A
    seeds.at<std::uint8_t>(0, 19) = 255; // outside every part
    const cv::Mat eight = partsHolding(mask, seeds, 8);
    EXPECT_EQ(cv::countNonZero(eight), 16 + 9);  // A and B are one part
    const cv::Mat four = partsHolding(mask, seeds, 4);
    EXPECT_EQ(cv::countNonZero(four), 16);
    EXPECT_EQ(cv::countNonZero(four(cv::Rect(2, 2, 4, 4))), 16);
    EXPECT_EQ(cv::countNonZero(partsHolding(mask, cv::Mat::zeros(20, 20, CV_8U))), 0);
}

}  // namespace
}  // namespace icewatch::volume
