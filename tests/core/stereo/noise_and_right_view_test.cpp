#include <tuple>
#include <utility>

#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/stereo/stages.hpp"

namespace icewatch::stereo::detail {
namespace {

// A smooth ramp (no noise: Immerkær's operator cancels it exactly) plus Gaussian noise of sigma.
cv::Mat noisyRamp(double sigma, std::uint64_t seed) {
    cv::Mat ramp(240, 320, CV_32F);
    for (int y = 0; y < ramp.rows; ++y)
        for (int x = 0; x < ramp.cols; ++x) ramp.at<float>(y, x) = 60.0f + 0.3f * static_cast<float>(x) + 0.1f * static_cast<float>(y);
    cv::Mat noise(ramp.size(), CV_32F);
    cv::RNG(seed).fill(noise, cv::RNG::NORMAL, 0.0, sigma);
    cv::Mat grey;
    cv::Mat(ramp + noise).convertTo(grey, CV_8U);
    return grey;
}

TEST(NoiseSmoothing, EstimatesTheNoiseOfAFlatImage) {
    // The 5th percentile of the block means reads low by design, about 3/4 of sigma on pure
    // noise (the smoothing rule is calibrated on this scale); what matters is that it is
    // proportional and that a clean image reads near zero.
    EXPECT_LT(estimateNoiseSigma(noisyRamp(0.0, 1)), 0.6);
    const double four = estimateNoiseSigma(noisyRamp(4.0, 2));
    EXPECT_GT(four, 0.65 * 4.0);
    EXPECT_LT(four, 0.9 * 4.0);
    const double eight = estimateNoiseSigma(noisyRamp(8.0, 3));
    EXPECT_GT(eight, 0.65 * 8.0);
    EXPECT_LT(eight, 0.9 * 8.0);
    EXPECT_NEAR(eight / four, 2.0, 0.2);
}

TEST(NoiseSmoothing, CensusBandFollowsTheNoiseOfBothEyes) {
    EXPECT_EQ(noiseAdaptiveCensusAlpha(1, 0.0, 5.0, 5.0), 1);   // off
    EXPECT_EQ(noiseAdaptiveCensusAlpha(1, 1.5, 0.7, 0.7), 1);   // a clean camera keeps the band
    EXPECT_EQ(noiseAdaptiveCensusAlpha(2, 1.5, 0.2, 0.2), 2);   // never below the configured one
    EXPECT_EQ(noiseAdaptiveCensusAlpha(1, 1.5, 1.2, 1.3), 2);
    EXPECT_EQ(noiseAdaptiveCensusAlpha(1, 1.5, 1.8, 1.8), 3);
    // One band from the mean, whichever eye is noisier.
    EXPECT_EQ(noiseAdaptiveCensusAlpha(1, 1.5, 0.4, 3.6), noiseAdaptiveCensusAlpha(1, 1.5, 3.6, 0.4));
    EXPECT_EQ(noiseAdaptiveCensusAlpha(1, 1.5, 1000.0, 1000.0), 32);  // capped
}

TEST(NoiseSmoothing, BlursOnlyNoisyImages) {
    cv::Mat grey = noisyRamp(0.0, 4), bgr;
    cv::cvtColor(grey, bgr, cv::COLOR_GRAY2BGR);
    const cv::Mat before = bgr.clone();
    EXPECT_EQ(smoothNoise(bgr, grey, 0.3), 0.0);
    EXPECT_EQ(cv::norm(bgr, before, cv::NORM_INF), 0.0);

    EXPECT_EQ(cv::norm(grey, noisyRamp(0.0, 4), cv::NORM_INF), 0.0);

    grey = noisyRamp(6.0, 5);
    cv::cvtColor(grey, bgr, cv::COLOR_GRAY2BGR);
    const double noiseBefore = estimateNoiseSigma(grey);
    EXPECT_DOUBLE_EQ(smoothNoise(bgr, grey, 0.3), 0.8);  // 0.3 * (about 4.5 - 1), capped at 0.8
    EXPECT_LT(estimateNoiseSigma(grey), 0.6 * noiseBefore);
    EXPECT_EQ(smoothNoise(bgr, grey, 0.0), 0.0);  // gain 0: off
}

TEST(NoiseSmoothing, TheFlattestBlocksReadLowerThanTheUsualPercentile) {
    const cv::Mat grey = noisyRamp(4.0, 6);
    const double first = estimateNoiseSigma(grey, 1.0);
    EXPECT_GT(first, 0.5 * 4.0);
    EXPECT_LT(first, estimateNoiseSigma(grey));
    EXPECT_DOUBLE_EQ(estimateNoiseSigma(grey, 5.0), estimateNoiseSigma(grey));
}

TEST(NoiseSmoothing, GreyPassSmoothsNoiseTooLightForTheBlur) {
    // Noise of sigma 2 is below what the colour blur acts on, but its flattest blocks read more
    // than one grey level: only the grey image (the Census input) is filtered.
    cv::Mat grey = noisyRamp(2.0, 7), bgr;
    cv::cvtColor(grey, bgr, cv::COLOR_GRAY2BGR);
    const cv::Mat bgrBefore = bgr.clone();
    const double noiseBefore = estimateNoiseSigma(grey);
    EXPECT_GT(estimateNoiseSigma(grey, 1.0), 1.0);
    EXPECT_EQ(smoothNoise(bgr, grey, 0.3), 0.0);
    EXPECT_EQ(cv::norm(bgr, bgrBefore, cv::NORM_INF), 0.0);
    EXPECT_LT(estimateNoiseSigma(grey), 0.6 * noiseBefore);
    EXPECT_EQ(smoothNoise(bgr, grey, 0.0), 0.0);  // gain 0: off

    // A step of ten noise sigmas keeps its contrast (the bilateral filter does not average across
    // it).
    cv::Mat step = noisyRamp(2.0, 8);
    step.colRange(step.cols / 2, step.cols) += 20;
    cv::cvtColor(step, bgr, cv::COLOR_GRAY2BGR);
    smoothNoise(bgr, step, 0.3);
    const int edge = step.cols / 2;
    const double across = cv::mean(step.col(edge))[0] - cv::mean(step.col(edge - 1))[0];
    EXPECT_GT(across, 20.0 + 0.3 - 3.0);  // the ramp adds 0.3 per column
}

TEST(NoiseSmoothing, ReportsTheNoiseItLeaves) {
    // Each way through: left alone, blurred, grey pass, off. The noise handed back is the
    // estimate of the grey image as it is left.
    for (const auto& [sigma, gain] : {std::pair{0.0, 0.3}, std::pair{6.0, 0.3}, std::pair{2.0, 0.3}, std::pair{2.0, 0.0}}) {
        cv::Mat grey = noisyRamp(sigma, 9), bgr;
        cv::cvtColor(grey, bgr, cv::COLOR_GRAY2BGR);
        double noiseLeft = -1.0;
        smoothNoise(bgr, grey, gain, 3.0, &noiseLeft);
        EXPECT_DOUBLE_EQ(noiseLeft, estimateNoiseSigma(grey)) << sigma << " " << gain;
    }
}

TEST(RightViewCosts, MirroredDiagonalsOfTheLeftVolume) {
    CostVolume left;
    left.create(5, 2, 3);
    for (int y = 0; y < 2; ++y)
        for (int x = 0; x < 5; ++x)
            for (int d = 0; d < left.stride; ++d) left.at(x, y)[d] = static_cast<std::uint16_t>(100 * y + 10 * x + d);
    CostVolume right;
    rightViewCosts(left, 999, right);
    // Right pixel x = 1 at d = 2 is left pixel 3 at d = 2, stored at column 5 - 1 - 1 = 3.
    EXPECT_EQ(right.at(3, 1)[2], 100 + 30 + 2);
    EXPECT_EQ(right.at(4, 0)[0], 0);       // right x = 0, d = 0: left x = 0
    // Right pixel x = 4 (the last) has no left partner beyond d = 0.
    EXPECT_EQ(right.at(0, 0)[0], 40);
    EXPECT_EQ(right.at(0, 0)[1], 999);
    EXPECT_EQ(right.at(0, 0)[2], 999);
    EXPECT_EQ(right.at(0, 0)[right.stride - 1], kPadCost);
}

// The transposing kernel against the definition, one value at a time: widths that are and are not
// whole blocks, disparity counts with and without padding, more disparities than pixels; the left
// volume's padded lanes hold junk, which must not come through.
TEST(RightViewCosts, OptimisedEqualsThePlainDiagonals) {
    for (const auto& [width, height, disparities] :
         {std::tuple{631, 7, 64}, std::tuple{631, 3, 37}, std::tuple{13, 2, 16}, std::tuple{5, 2, 64},
          std::tuple{16, 1, 9}, std::tuple{1, 1, 1}}) {
        CostVolume left;
        left.create(width, height, disparities);
        cv::RNG rng(static_cast<std::uint64_t>(width * 100 + disparities));
        for (auto& c : left.data) c = static_cast<std::uint16_t>(rng.uniform(0, 65536));
        CostVolume fast;
        rightViewCosts(left, 999, fast);
        bool same = fast.width == width && fast.height == height && fast.stride == left.stride;
        for (int y = 0; y < height && same; ++y)
            for (int x = 0; x < width && same; ++x) {
                const std::uint16_t* cell = fast.at(width - 1 - x, y);
                for (int d = 0; d < left.stride; ++d) {
                    const std::uint16_t expected =
                        d >= disparities ? kPadCost : (x + d < width ? left.at(x + d, y)[d] : std::uint16_t{999});
                    same = same && cell[d] == expected;
                }
            }
        EXPECT_TRUE(same) << width << "x" << height << ", " << disparities << " disparities";
    }
}

}  // namespace
}  // namespace icewatch::stereo::detail
