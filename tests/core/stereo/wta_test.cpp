#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "core/stereo/stages.hpp"

namespace icewatch::stereo::detail {
namespace {

// Random aggregated costs over a small range, so equal costs (ties) are frequent and the
// smaller-disparity rule is exercised; padded lanes as the matcher leaves them.
CostVolume randomVolume(int width, int height, int disparities, std::uint64_t seed) {
    CostVolume costs;
    costs.create(width, height, disparities);
    cv::RNG rng(seed);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            std::uint16_t* c = costs.at(x, y);
            for (int d = 0; d < costs.stride; ++d) {
                c[d] = d < disparities ? static_cast<std::uint16_t>(rng.uniform(0, 40)) : kPadCost;
            }
        }
    return costs;
}

TEST(WinnerTakesAll, OptimisedEqualsReference) {
    for (int disparities : {1, 5, 11, 16, 64}) {
        const CostVolume costs = randomVolume(631, 47, disparities, 100 + static_cast<std::uint64_t>(disparities));
        cv::Mat fastLeft, fastRight, plainLeft, plainRight;
        winnerTakesAll(costs, fastLeft, fastRight);
        winnerTakesAllReference(costs, plainLeft, plainRight);
        EXPECT_EQ(cv::countNonZero(fastLeft != plainLeft), 0) << disparities;
        EXPECT_EQ(cv::countNonZero(fastRight != plainRight), 0) << disparities;
    }
}

TEST(WinnerTakesAll, TiesGoToTheSmallerDisparity) {
    CostVolume costs;
    costs.create(12, 1, 9);
    std::fill(costs.data.begin(), costs.data.end(), 7);
    cv::Mat left, right;
    winnerTakesAll(costs, left, right);
    for (int x = 0; x < 12; ++x) {
        EXPECT_EQ(left.at<std::int16_t>(0, x), 0);
        EXPECT_EQ(right.at<std::int16_t>(0, x), 0);
    }
}

}  // namespace
}  // namespace icewatch::stereo::detail
