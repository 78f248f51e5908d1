#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "core/stereo/stages.hpp"
#include "tests/core/stereo/stereo_test_images.hpp"

namespace icewatch::stereo::detail {
namespace {

struct Pair {
    cv::Mat bgrLeft, bgrRight, greyLeft, greyRight;
};

Pair randomPair(int width, int height) {
    Pair p;
    p.bgrLeft = test::randomImage(width, height, CV_8UC3, 1);
    p.bgrRight = test::randomImage(width, height, CV_8UC3, 2);
    cv::cvtColor(p.bgrLeft, p.greyLeft, cv::COLOR_BGR2GRAY);
    cv::cvtColor(p.bgrRight, p.greyRight, cv::COLOR_BGR2GRAY);
    return p;
}

// What the paper's cost stage reads of a pair: both eyes' improved Census codes (band 2), the
// gradient magnitudes, the left window mask at the given threshold.
struct PaperInputs {
    CensusImage censusLeft, censusRight;
    CostInputs left, right;

    PaperInputs(const Pair& p, const Parameters& parameters, double windowThreshold)
        : left{p.bgrLeft, channelGradientMagnitudes(p.bgrLeft), censusWindowMask(p.greyLeft, windowThreshold),
               &censusLeft},
          right{p.bgrRight, channelGradientMagnitudes(p.bgrRight), cv::Mat(), &censusRight} {
        improvedCensus(p.greyLeft, edgeCornerBits(p.greyLeft, parameters), 2, left.windowMask, censusLeft);
        improvedCensus(p.greyRight, edgeCornerBits(p.greyRight, parameters), 2, cv::Mat(), censusRight);
    }
    PaperInputs(const PaperInputs&) = delete;  // the inputs point at this object's own codes
    PaperInputs& operator=(const PaperInputs&) = delete;
};

// A narrower band or a smaller region gives its memory back; the same size keeps the buffer.
TEST(Costs, VolumesAreSizedExactlyByTheViewAndTheBandsWidth) {
    CostVolume v;
    v.create(100, 20, 128);
    EXPECT_EQ(v.data.capacity(), std::size_t{100} * 20 * 128);
    const std::uint16_t* before = v.data.data();
    v.create(100, 20, 128);
    EXPECT_EQ(v.data.data(), before);
    v.create(80, 20, 32);
    EXPECT_EQ(v.stride, 32);
    EXPECT_EQ(v.data.size(), std::size_t{80} * 20 * 32);
    EXPECT_EQ(v.data.capacity(), v.data.size());
    CensusImage census;
    census.create(100, 20, kImprovedCensusWords);
    census.create(60, 20, kImprovedCensusWords);
    EXPECT_EQ(census.data.capacity(), std::size_t{60} * 20 * kImprovedCensusWords);
}

// A column view of Census codes reads the stored columns from its first one on.
TEST(Costs, CensusViewReadsItsColumnsOfTheWholeImage) {
    CensusImage census;
    census.create(10, 3, 1);
    for (int y = 0; y < 3; ++y)
        for (int x = 0; x < 10; ++x) *census.at(x, y) = static_cast<std::uint64_t>(100 * y + x);
    census.viewColumns(4, 6);
    EXPECT_EQ(census.width, 6);
    EXPECT_EQ(*census.at(0, 0), 4u);
    EXPECT_EQ(*census.at(5, 2), 209u);
}

TEST(Costs, PaperOptimisedEqualsReference) {
    const Pair p = randomPair(631, 479);
    const Parameters parameters;
    const PaperInputs inputs(p, parameters, 6.0);
    const CostInputs& left = inputs.left;
    const CostInputs& right = inputs.right;
    for (int disparities : {13, 24}) {
        CostVolume fast, plain;
        fast.create(631, 479, disparities);
        plain.create(631, 479, disparities);
        paperCost(left, right, parameters, fast);
        paperCostReference(left, right, parameters, plain);
        EXPECT_EQ(fast.data, plain.data) << disparities;
    }
}

// The matcher's way: the Census codes made row by row as the costs need them, on column views of a
// band (left from column `first` on, right from 0) as the matcher passes them, for both methods.
// The costs equal those of the whole images' codes, cell for cell.
TEST(Costs, CodesMadeRowByRowGiveTheWholeImagesCosts) {
    const Pair p = randomPair(203, 61);
    const Parameters parameters;
    const PaperInputs whole(p, parameters, 6.0);
    const int first = 9, width = p.bgrLeft.cols - first;
    const cv::Rect leftView(first, 0, width, p.bgrLeft.rows), rightView(0, 0, width, p.bgrLeft.rows);
    for (const bool paper : {true, false}) {
        CensusEncoder encoders[2];
        CensusImage codes[2];
        if (paper) {
            encoders[0].prepareImproved(p.greyLeft, edgeCornerBits(p.greyLeft, parameters), 2, whole.left.windowMask);
            encoders[1].prepareImproved(p.greyRight, edgeCornerBits(p.greyRight, parameters), 2, cv::Mat());
        } else {
            encoders[0].prepareMei(p.greyLeft);
            encoders[1].prepareMei(p.greyRight);
        }
        encoders[0].encodeRows(0, p.greyLeft.rows, codes[0]);
        encoders[1].encodeRows(0, p.greyRight.rows, codes[1]);
        codes[0].viewColumns(first, width);
        codes[1].viewColumns(0, width);
        const cv::Mat mask = whole.left.windowMask(leftView);
        const CostInputs byImageLeft{p.bgrLeft(leftView), whole.left.gradient(leftView), mask, &codes[0]};
        const CostInputs byImageRight{p.bgrRight(rightView), whole.right.gradient(rightView), cv::Mat(), &codes[1]};
        const CostInputs byRowLeft{byImageLeft.bgr, byImageLeft.gradient, mask, nullptr, &encoders[0], first};
        const CostInputs byRowRight{byImageRight.bgr, byImageRight.gradient, cv::Mat(), nullptr, &encoders[1], 0};
        CostVolume byImage, byRow;
        byImage.create(width, p.bgrLeft.rows, 21);
        byRow.create(width, p.bgrLeft.rows, 21);
        if (paper) {
            paperCost(byImageLeft, byImageRight, parameters, byImage);
            paperCost(byRowLeft, byRowRight, parameters, byRow);
        } else {
            adCensusCost(byImageLeft, byImageRight, parameters, byImage);
            adCensusCost(byRowLeft, byRowRight, parameters, byRow);
        }
        EXPECT_EQ(byRow.data, byImage.data) << (paper ? "paper" : "AD-Census");
    }
}

// The matcher's order: each cost row, as soon as it is complete, gives the right view's row and goes
// through the first aggregation pass of both views; aggregation then carries on from there. The
// result equals the stages run one after the other over whole volumes, by their references.
TEST(Costs, RowsHandedOnAsTheyCompleteGiveTheSameAggregation) {
    Pair p = randomPair(211, 97);
    cv::GaussianBlur(p.bgrLeft, p.bgrLeft, cv::Size(0, 0), 2.0);  // long arms, several penalty cases
    cv::GaussianBlur(p.bgrRight, p.bgrRight, cv::Size(0, 0), 2.0);
    cv::cvtColor(p.bgrLeft, p.greyLeft, cv::COLOR_BGR2GRAY);
    cv::cvtColor(p.bgrRight, p.greyRight, cv::COLOR_BGR2GRAY);
    const Parameters parameters;
    const PaperInputs inputs(p, parameters, 0.5);
    const CostInputs& left = inputs.left;
    const CostInputs& right = inputs.right;
    cv::Mat mirroredRight;
    cv::flip(p.bgrRight, mirroredRight, 1);
    CrossArms leftArms, rightArms;
    computeCrossArms(p.bgrLeft, parameters, leftArms);
    computeCrossArms(mirroredRight, parameters, rightArms);
    for (const int iterations : {1, 2}) {
        CostVolume costs, rightCosts;
        costs.create(211, 97, 40);
        rightCosts.create(211, 97, 40);
        std::vector<int> calls(97, 0);
        paperCost(left, right, parameters, costs, [&](int y) {
            ++calls[static_cast<std::size_t>(y)];
            rightViewCostsRow(costs, kPaperInvalidCost, rightCosts, y);
            meanAlongRow(leftArms, costs, y);
            meanAlongRow(rightArms, rightCosts, y);
        });
        EXPECT_EQ(calls, std::vector<int>(97, 1));
        aggregateCross(leftArms, iterations, costs, true);
        aggregateCross(rightArms, iterations, rightCosts, true);

        CostVolume plain, plainRight;
        plain.create(211, 97, 40);
        paperCostReference(left, right, parameters, plain);
        rightViewCosts(plain, kPaperInvalidCost, plainRight);
        aggregateCrossReference(leftArms, iterations, plain);
        aggregateCrossReference(rightArms, iterations, plainRight);
        EXPECT_EQ(costs.data, plain.data) << iterations;
        EXPECT_EQ(rightCosts.data, plainRight.data) << iterations;
    }
}

// λs so large that the AD and gradient terms never saturate: the optimised kernel looks them up
// apart instead of from one summed table.
TEST(Costs, PaperOptimisedEqualsReferenceWithUnsaturatedTerms) {
    const Pair p = randomPair(211, 97);
    Parameters parameters;
    parameters.lambdaAd = 400.0;
    parameters.lambdaGradient = 40.0;
    const PaperInputs inputs(p, parameters, 6.0);
    const CostInputs& left = inputs.left;
    const CostInputs& right = inputs.right;
    CostVolume fast, plain;
    fast.create(211, 97, 40);
    plain.create(211, 97, 40);
    paperCost(left, right, parameters, fast);
    paperCostReference(left, right, parameters, plain);
    EXPECT_EQ(fast.data, plain.data);
}

TEST(Costs, AdCensusOptimisedEqualsReference) {
    const Pair p = randomPair(631, 479);
    CensusImage censusLeft, censusRight;
    meiCensus(p.greyLeft, censusLeft);
    meiCensus(p.greyRight, censusRight);
    CostInputs left{p.bgrLeft, {}, {}, &censusLeft};
    CostInputs right{p.bgrRight, {}, {}, &censusRight};
    CostVolume fast, plain;
    fast.create(631, 479, 21);
    plain.create(631, 479, 21);
    adCensusCost(left, right, Parameters{}, fast);
    adCensusCostReference(left, right, Parameters{}, plain);
    EXPECT_EQ(fast.data, plain.data);
}

TEST(Costs, IdenticalPixelsCostNothingAndTermsFuseAsThePaperSays) {
    // One-row images: left pixel 2 equals right pixel 0 (d = 2) exactly; at d = 1 the colours
    // differ by 10 in each channel.
    cv::Mat left(1, 3, CV_8UC3, cv::Scalar(100, 100, 100)), right(1, 3, CV_8UC3, cv::Scalar(100, 100, 100));
    right.at<cv::Vec3b>(0, 1) = {110, 110, 110};
    cv::Mat grey;
    cv::Mat zeroGradient = cv::Mat::zeros(1, 3, CV_8UC3);
    CensusImage censusLeft, censusRight;
    censusLeft.create(3, 1, kImprovedCensusWords);
    censusRight.create(3, 1, kImprovedCensusWords);
    std::fill(censusLeft.data.begin(), censusLeft.data.end(), 0);
    std::fill(censusRight.data.begin(), censusRight.data.end(), 0);
    censusRight.at(1, 0)[kCensus9Offset] = 0xF;  // 4 bits differ in the 9x9 code
    const Parameters parameters;
    CostInputs l{left, zeroGradient, cv::Mat::zeros(1, 3, CV_8UC1), &censusLeft};
    CostInputs r{right, zeroGradient, cv::Mat(), &censusRight};
    CostVolume volume;
    volume.create(3, 1, 3);
    paperCost(l, r, parameters, volume);
    EXPECT_EQ(volume.at(2, 0)[2], 0);
    const double expected = (1.0 - std::exp(-4.0 / parameters.lambdaCensus)) + (1.0 - std::exp(-30.0 / parameters.lambdaAd));
    EXPECT_NEAR(volume.at(2, 0)[1] / double(kCostScale), expected, 2.0 / kCostScale);
    EXPECT_EQ(volume.at(0, 0)[1], 3 * kCostScale);  // no right pixel at x - d < 0
    EXPECT_EQ(volume.at(0, 0)[7], kPadCost);        // the padded disparity lanes
}

}  // namespace
}  // namespace icewatch::stereo::detail
