#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "core/stereo/stages.hpp"
#include "tests/core/stereo/stereo_test_images.hpp"

namespace icewatch::stereo::detail {
namespace {

cv::Mat greyRow(const std::vector<int>& values) {
    cv::Mat row(1, static_cast<int>(values.size()), CV_8UC3);
    for (int x = 0; x < row.cols; ++x) row.at<cv::Vec3b>(0, x) = cv::Vec3b::all(static_cast<std::uint8_t>(values[static_cast<std::size_t>(x)]));
    return row;
}

// Mei's values, which the expectations below are worked out for.
Parameters meiArms() {
    Parameters p;
    p.crossTau1 = 20;
    p.crossTau2 = 6;
    p.crossL1 = 34;
    p.crossL2 = 17;
    return p;
}

int rightArm(const std::vector<int>& values) {
    CrossArms arms;
    computeCrossArms(greyRow(values), meiArms(), arms);
    return arms.right.at<std::uint8_t>(0, 0);
}

TEST(CrossArms, RulesOfMei) {
    // Flat: only D_s < L1 stops the arm, at L1 - 1 = 33.
    EXPECT_EQ(rightArm(std::vector<int>(60, 100)), 33);
    // A ramp of 1 grey level per pixel: colour stays below τ1 = 20 up to 19 px, but beyond
    // L2 = 17 the tighter τ2 = 6 applies: the arm ends at 17.
    std::vector<int> ramp(40);
    for (int x = 0; x < 40; ++x) ramp[static_cast<std::size_t>(x)] = 100 + x;
    EXPECT_EQ(rightArm(ramp), 17);
    // A pixel too different from p (25 >= τ1) stops it.
    EXPECT_EQ(rightArm({100, 100, 100, 125, 100, 100}), 2);
    // A pixel close to p (5) but too different from its predecessor (20 >= τ1) stops it too.
    EXPECT_EQ(rightArm({100, 100, 115, 95, 100, 100}), 2);
}

TEST(CrossArms, DrawnRegion) {
    // A 6x4 white rectangle on black: an inside pixel's arms reach the rectangle's border.
    cv::Mat image(12, 16, CV_8UC3, cv::Scalar::all(0));
    image(cv::Rect(5, 4, 6, 4)).setTo(cv::Scalar::all(255));
    CrossArms arms;
    computeCrossArms(image, meiArms(), arms);
    EXPECT_EQ(arms.left.at<std::uint8_t>(5, 7), 2);
    EXPECT_EQ(arms.right.at<std::uint8_t>(5, 7), 3);
    EXPECT_EQ(arms.up.at<std::uint8_t>(5, 7), 1);
    EXPECT_EQ(arms.down.at<std::uint8_t>(5, 7), 2);
    EXPECT_EQ(arms.left.at<std::uint8_t>(0, 0), 0);  // image border
    EXPECT_EQ(arms.right.at<std::uint8_t>(0, 0), 15);
}

TEST(CrossArms, OptimisedEqualsReference) {
    const cv::Mat image = test::randomImage(631, 479, CV_8UC3, 8);
    for (const Parameters& p : {Parameters{}, meiArms()}) {
        CrossArms fast, plain;
        computeCrossArms(image, p, fast);
        computeCrossArmsReference(image, p, plain);
        for (auto [a, b] : {std::pair{&fast.left, &plain.left}, {&fast.right, &plain.right}, {&fast.up, &plain.up},
                            {&fast.down, &plain.down}}) {
            EXPECT_EQ(cv::norm(*a, *b, cv::NORM_INF), 0.0);
        }
    }
}

TEST(CrossAggregation, RegionMeanOverAFlatImage) {
    // Uniform colour: every region is the whole 5x5 image, so one cost of 2500 averages to 100.
    const cv::Mat image(5, 5, CV_8UC3, cv::Scalar::all(80));
    CrossArms arms;
    computeCrossArms(image, Parameters{}, arms);
    CostVolume costs;
    costs.create(5, 5, 2);
    std::fill(costs.data.begin(), costs.data.end(), 0);
    costs.at(1, 3)[0] = 2500;
    aggregateCross(arms, 1, costs);
    for (int y = 0; y < 5; ++y)
        for (int x = 0; x < 5; ++x) {
            EXPECT_EQ(costs.at(x, y)[0], 100);
            EXPECT_EQ(costs.at(x, y)[1], 0);
            EXPECT_EQ(costs.at(x, y)[2], kPadCost);
        }
}

TEST(CrossAggregation, OptimisedEqualsReference) {
    // Raw noise gives arms of a pixel or two; blurred, arms run up to L1 and windows overlap.
    const cv::Mat noise = test::randomImage(631, 479, CV_8UC3, 3);
    cv::Mat smooth;
    cv::GaussianBlur(noise, smooth, cv::Size(0, 0), 3.0);
    for (const cv::Mat& image : {noise, smooth}) {
        CrossArms arms;
        computeCrossArms(image, Parameters{}, arms);
        CostVolume fast, plain;
        fast.create(631, 479, 13);
        cv::RNG rng(4);
        for (auto& c : fast.data) c = static_cast<std::uint16_t>(rng.uniform(0, 3 * kCostScale + 1));
        for (int y = 0; y < 479; ++y)
            for (int x = 0; x < 631; ++x) std::fill(fast.at(x, y) + 13, fast.at(x, y) + fast.stride, kPadCost);
        plain = fast;
        aggregateCross(arms, 2, fast);
        aggregateCrossReference(arms, 2, plain);
        EXPECT_EQ(fast.data, plain.data);
    }
}

TEST(CrossAggregation, OptimisedEqualsReferenceOnNarrowImages) {
    // The vertical pass sums blocks of neighbouring columns of each of the 16 stripes: widths that
    // leave stripes of 1-3, 4-7 and 8 or more columns, 3 iterations (both orders, then the first
    // again) and an axis without padding (32) besides a padded one (5).
    for (const cv::Size size : {cv::Size(37, 29), cv::Size(101, 17), cv::Size(203, 41)}) {
        const cv::Mat noise = test::randomImage(size.width, size.height, CV_8UC3, 5);
        cv::Mat smooth;
        cv::GaussianBlur(noise, smooth, cv::Size(0, 0), 2.0);
        for (const cv::Mat& image : {noise, smooth}) {
            CrossArms arms;
            computeCrossArms(image, Parameters{}, arms);
            for (const int disparities : {5, 32}) {
                CostVolume fast, plain;
                fast.create(size.width, size.height, disparities);
                cv::RNG rng(7);
                for (auto& c : fast.data) c = static_cast<std::uint16_t>(rng.uniform(0, 3 * kCostScale + 1));
                for (int y = 0; y < size.height; ++y)
                    for (int x = 0; x < size.width; ++x) {
                        std::fill(fast.at(x, y) + disparities, fast.at(x, y) + fast.stride, kPadCost);
                    }
                plain = fast;
                aggregateCross(arms, 3, fast);
                aggregateCrossReference(arms, 3, plain);
                EXPECT_EQ(fast.data, plain.data) << size << " " << disparities;
            }
        }
    }
}

}  // namespace
}  // namespace icewatch::stereo::detail
