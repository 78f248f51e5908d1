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

// Parts at least 1/n of the largest are kept whole, smaller ones dropped; an empty mask stays empty.
TEST(MaskParts, LargePartsKeepsThoseNearTheLargestsSize) {
    cv::Mat mask = cv::Mat::zeros(40, 40, CV_8U);
    mask(cv::Rect(2, 2, 10, 10)).setTo(255);   // 100 px, the largest
    mask(cv::Rect(20, 2, 5, 4)).setTo(255);    // 20 px: a fifth of it
    mask(cv::Rect(30, 30, 3, 3)).setTo(255);   // 9 px
    const cv::Mat kept = largeParts(mask, 5);
    EXPECT_EQ(cv::countNonZero(kept), 100 + 20);
    EXPECT_EQ(cv::countNonZero(kept(cv::Rect(30, 30, 3, 3))), 0);
    EXPECT_EQ(cv::countNonZero(largeParts(mask, 20)), 100 + 20 + 9);
    EXPECT_EQ(cv::countNonZero(largeParts(cv::Mat::zeros(8, 8, CV_8U), 2)), 0);
}

}  // namespace
}  // namespace icewatch::volume
