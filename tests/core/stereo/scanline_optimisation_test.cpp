#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "core/stereo/stages.hpp"
#include "tests/core/stereo/stereo_test_images.hpp"

namespace icewatch::stereo::detail {
namespace {

TEST(ScanlinePenalties, ThreeCasesFromTheColourDifferences) {
    Parameters parameters;
    parameters.scanlinePi1 = 1.0;
    parameters.scanlinePi2 = 3.0;
    parameters.scanlineTau = 15;
    const ScanlinePenalties p = scanlinePenalties(parameters);
    EXPECT_EQ(penaltyCase(3, 14, 15), 0);   // both below: Π
    EXPECT_EQ(penaltyCase(15, 2, 15), 1);   // one: Π/4
    EXPECT_EQ(penaltyCase(2, 40, 15), 1);
    EXPECT_EQ(penaltyCase(20, 15, 15), 2);  // neither: Π/10
    EXPECT_EQ(p.p1[0], 512);
    EXPECT_EQ(p.p2[0], 1536);
    EXPECT_EQ(p.p1[1], 128);
    EXPECT_EQ(p.p2[1], 384);
    EXPECT_EQ(p.p1[2], 51);   // 51.2
    EXPECT_EQ(p.p2[2], 154);  // 153.6
}

// One step of L_r(p, d) = C(p, d) + min(L(d), L(d±1) + P1, min L + P2) - min L, by hand.
TEST(ScanlineStep, EachPenaltyCase) {
    const std::uint16_t previous[4] = {100, 40, 300, 900};  // min 40 at d = 1
    const std::uint16_t cost[4] = {10, 20, 30, 40};
    std::uint16_t out[4];
    // Π case (P1 = 512, P2 = 1536): d = 0 keeps its own 100; d = 2 takes 40 + 512 > 300, keeps
    // 300; d = 3: min(900, 300 + 512, 40 + 1536) = 812.
    scanlineStep(cost, previous, 4, 512, 1536, out);
    EXPECT_EQ(out[0], 10 + 100 - 40);
    EXPECT_EQ(out[1], 20 + 40 - 40);
    EXPECT_EQ(out[2], 30 + 300 - 40);
    EXPECT_EQ(out[3], 40 + 812 - 40);
    // Π/4 (128, 384): d = 0: min(100, 40 + 128) = 100; d = 2: min(300, 40 + 128) = 168;
    // d = 3: min(900, 300 + 128, 40 + 384) = 424.
    scanlineStep(cost, previous, 4, 128, 384, out);
    EXPECT_EQ(out[0], 10 + 100 - 40);
    EXPECT_EQ(out[2], 30 + 168 - 40);
    EXPECT_EQ(out[3], 40 + 424 - 40);
    // Π/10 (51, 154): d = 0: min(100, 91) = 91; d = 2: 91; d = 3: min(900, 351, 194) = 194.
    scanlineStep(cost, previous, 4, 51, 154, out);
    EXPECT_EQ(out[0], 10 + 91 - 40);
    EXPECT_EQ(out[2], 30 + 91 - 40);
    EXPECT_EQ(out[3], 40 + 194 - 40);
}

TEST(ScanlineOptimisation, OptimisedEqualsReference) {
    // Raw noise has almost every colour difference above τ_SO; blurred, all three penalty cases
    // occur, on every direction.
    const cv::Mat noise = test::randomImage(631, 479, CV_8UC3, 5);
    cv::Mat smooth;
    cv::GaussianBlur(noise, smooth, cv::Size(0, 0), 2.0);
    for (const cv::Mat& image : {noise, smooth})
        for (int disparities : {11, 16, 40})
            for (int directions : {8, 4}) {
                CostVolume costs;
                costs.create(631, 479, disparities);
                cv::RNG rng(6);
                for (auto& c : costs.data) c = static_cast<std::uint16_t>(rng.uniform(0, 3 * kCostScale + 1));
                for (int y = 0; y < 479; ++y)
                    for (int x = 0; x < 631; ++x)
                        std::fill(costs.at(x, y) + disparities, costs.at(x, y) + costs.stride, kPadCost);
                const ScanlinePenalties penalties = scanlinePenalties(Parameters{});
                CostVolume fast, plain;
                aggregateScanlines(costs, image, penalties, fast, directions);
                aggregateScanlinesReference(costs, image, penalties, plain, directions);
                EXPECT_EQ(fast.data, plain.data) << disparities << " disparities, " << directions << " directions";
            }
}

// The winner taken as each pixel's sum is completed equals the winner-take-all of the finished
// volume, ties included: costs drawn from a few values make equal sums common, and a flat volume
// is all ties (every pixel takes d = 0).
TEST(ScanlineOptimisation, WinnersOnTheWayEqualWinnerTakesAll) {
    const cv::Mat image = test::randomImage(203, 37, CV_8UC3, 8);
    cv::Mat smooth;
    cv::GaussianBlur(image, smooth, cv::Size(0, 0), 2.0);
    const ScanlinePenalties penalties = scanlinePenalties(Parameters{});
    for (int disparities : {1, 11, 16, 40, 64})
        for (int values : {1, 3, 3 * kCostScale})
            for (int directions : {8, 4}) {
                CostVolume costs;
                costs.create(203, 37, disparities);
                cv::RNG rng(static_cast<std::uint64_t>(disparities * 7 + values));
                for (int y = 0; y < 37; ++y)
                    for (int x = 0; x < 203; ++x) {
                        std::uint16_t* c = costs.at(x, y);
                        for (int d = 0; d < costs.stride; ++d) {
                            c[d] = d < disparities ? static_cast<std::uint16_t>(rng.uniform(0, values) * (kCostScale / 4))
                                                   : kPadCost;
                        }
                    }
                CostVolume sum;
                cv::Mat onTheWay, left, right;
                aggregateScanlines(costs, smooth, penalties, sum, directions, nullptr, &onTheWay);
                winnerTakesAllReference(sum, left, right);
                ASSERT_EQ(onTheWay.type(), CV_16SC1);
                EXPECT_EQ(cv::countNonZero(onTheWay != left), 0)
                    << disparities << " disparities, " << values << " cost values, " << directions << " directions";
                if (values == 1) {
                    EXPECT_EQ(cv::countNonZero(onTheWay), 0);
                }
            }
}

TEST(ScanlineOptimisation, FourDirectionsLeaveOutTheDiagonals) {
    // A flat image (every penalty case 0) and zero cost except a column of high cost at x = 4,
    // d = 3. At (5, 4), d = 3, each path arriving from column 4 pays P1 to leave that cost
    // (stepping to d = 2 or 4, where it is free); paths from elsewhere pay nothing. With the axes
    // alone only left-to-right comes from column 4; with all 8, the two diagonals from the upper
    // and lower left do too.
    const cv::Mat image(9, 9, CV_8UC3, cv::Scalar(100, 100, 100));
    CostVolume costs;
    costs.create(9, 9, 8);
    std::fill(costs.data.begin(), costs.data.end(), std::uint16_t{0});
    for (int y = 0; y < 9; ++y) costs.at(4, y)[3] = 3 * kCostScale;  // above P1, below P2
    const ScanlinePenalties penalties = scanlinePenalties(Parameters{});
    CostVolume four, eight;
    aggregateScanlines(costs, image, penalties, four, 4);
    aggregateScanlines(costs, image, penalties, eight, 8);
    EXPECT_EQ(four.at(5, 4)[3], penalties.p1[0]);
    EXPECT_EQ(eight.at(5, 4)[3], 3 * penalties.p1[0]);
    EXPECT_THROW(aggregateScanlines(costs, image, penalties, four, 6), cv::Exception);
}

}  // namespace
}  // namespace icewatch::stereo::detail
