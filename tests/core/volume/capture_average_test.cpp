#include "core/volume/capture_average.hpp"

#include <cmath>

#include <opencv2/imgproc.hpp>
#include <gtest/gtest.h>

#include "core/common/error.hpp"

namespace icewatch::volume {
namespace {

// A textured side-by-side frame (both eyes alike), in floating point, shifted by `dx` pixels.
cv::Mat scene(double dx = 0.0) {
    cv::Mat base(240, 640, CV_32F);
    cv::RNG rng(11);
    rng.fill(base, cv::RNG::UNIFORM, 60, 190);
    cv::GaussianBlur(base, base, {0, 0}, 2.0);
    if (dx != 0.0) {
        const cv::Matx23d shift(1, 0, dx, 0, 1, 0);
        cv::warpAffine(base, base, shift, base.size(), cv::INTER_CUBIC, cv::BORDER_REFLECT);
    }
    return base;
}

cv::Mat noisyFrame(const cv::Mat& truth, double sigma, std::uint64_t seed) {
    cv::Mat noise(truth.size(), CV_32F);
    cv::RNG rng(seed);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, sigma);
    cv::Mat grey8;
    cv::Mat(truth + noise).convertTo(grey8, CV_8U);
    return grey8;
}

CaptureAverageOptions lenient() {
    CaptureAverageOptions o;
    o.health.minSharpness = 0.0;
    o.health.minContrast = 0.0;
    return o;
}

TEST(CaptureAverage, NoisyCopiesAverageToWithinSigmaOverRootN) {
    const cv::Mat truth = scene();
    const double sigma = 4.0;
    for (const int n : {1, 4, 16}) {
        std::vector<cv::Mat> frames;
        for (int i = 0; i < n; ++i) frames.push_back(noisyFrame(truth, sigma, 100 + i));
        const AveragedCapture a = averageCapture(frames, {}, lenient());
        ASSERT_EQ(a.framesUsed, n);
        ASSERT_EQ(a.frame.type(), CV_32FC1);
        const double rms = cv::norm(a.frame, truth, cv::NORM_L2) / std::sqrt(static_cast<double>(truth.total()));
        // σ/√N, plus the 8-bit rounding of each frame (1/√12 grey level, itself averaged down).
        const double expected = std::sqrt(sigma * sigma + 1.0 / 12.0) / std::sqrt(static_cast<double>(n));
        EXPECT_NEAR(rms, expected, 0.05 * expected) << n << " frames";
    }
}

TEST(CaptureAverage, TheNoiseDrawHasTheAveragesNoiseLevelAndNoneOfItsScene) {
    const cv::Mat truth = scene();
    const double sigma = 4.0;
    for (const int n : {2, 3, 4, 7, 16}) {
        std::vector<cv::Mat> frames;
        for (int i = 0; i < n; ++i) frames.push_back(noisyFrame(truth, sigma, 300 + i));
        const AveragedCapture a = averageCapture(frames, {}, lenient());
        ASSERT_EQ(a.noise.type(), CV_32FC1) << n << " frames";
        ASSERT_EQ(a.noise.size(), truth.size());
        const double root = std::sqrt(static_cast<double>(n));
        const double expected = std::sqrt(sigma * sigma + 1.0 / 12.0) / root;
        // Its level is the average's own, odd counts included.
        cv::Scalar mean, deviation;
        cv::meanStdDev(a.noise, mean, deviation);
        EXPECT_NEAR(deviation[0], expected, 0.05 * expected) << n << " frames";
        EXPECT_NEAR(mean[0], 0.0, 0.05 * expected) << n << " frames";
        // The scene cancels: the draw does not follow the scene's texture (a draw that kept a
        // frame's scene would correlate with it fully).
        cv::Mat sceneOff = truth - cv::mean(truth)[0];
        const double correlation = sceneOff.dot(a.noise) / (cv::norm(sceneOff) * cv::norm(a.noise));
        EXPECT_LT(std::abs(correlation), 0.02) << n << " frames";
    }
    // One frame has no second to tell its noise from its scene by.
    const AveragedCapture one = averageCapture({noisyFrame(truth, sigma, 1)}, {}, lenient());
    EXPECT_TRUE(one.noise.empty());
}

TEST(CaptureAverage, FramesThatMovedOrAreDarkAreLeftOutAndNamed) {
    const cv::Mat truth = scene();
    std::vector<cv::Mat> frames;
    std::vector<std::string> names;
    for (int i = 0; i < 8; ++i) {
        cv::Mat frame = noisyFrame(i == 3 ? scene(1.5) : truth, 2.0, 200 + i);  // frame 4: a gust moved it
        if (i == 6) frame = frame / 20;                                         // frame 7: dark
        frames.push_back(frame);
        names.push_back("f" + std::to_string(i + 1));
    }
    const AveragedCapture a = averageCapture(frames, names, lenient());
    EXPECT_EQ(a.framesUsed, 6);
    EXPECT_EQ(a.framesHealthy, 7);
    ASSERT_EQ(a.dropped.size(), 2u);
    EXPECT_EQ(a.dropped[0].flag, "dark");
    EXPECT_NE(a.dropped[0].reason.find("f7"), std::string::npos) << a.dropped[0].reason;
    EXPECT_EQ(a.dropped[1].flag, "moved");
    EXPECT_NE(a.dropped[1].reason.find("f4"), std::string::npos) << a.dropped[1].reason;
}

TEST(CaptureAverage, SomethingPassingThroughOneFrameLeavesItOut) {
    const cv::Mat truth = scene();
    std::vector<cv::Mat> frames;
    for (int i = 0; i < 6; ++i) frames.push_back(noisyFrame(truth, 2.0, 300 + i));
    cv::circle(frames[2], {150, 120}, 25, cv::Scalar(10), cv::FILLED);  // a bird
    const AveragedCapture a = averageCapture(frames, {}, lenient());
    EXPECT_EQ(a.framesUsed, 5);
    ASSERT_EQ(a.dropped.size(), 1u);
    EXPECT_EQ(a.dropped[0].flag, "disturbed");
    EXPECT_NE(a.dropped[0].reason.find("frame 3"), std::string::npos);
}

TEST(CaptureAverage, ADisturbedFirstFrameLosesToTheFramesAfterIt) {
    // The first frame is the reference the others are compared with as they come; when it is the
    // odd one out, the frames that agree with each other win and it is the one left out.
    const cv::Mat truth = scene();
    std::vector<cv::Mat> frames;
    for (int i = 0; i < 6; ++i) frames.push_back(noisyFrame(truth, 2.0, 400 + i));
    cv::circle(frames[0], {150, 120}, 25, cv::Scalar(10), cv::FILLED);  // a bird in the first frame
    const AveragedCapture a = averageCapture(frames, {}, lenient());
    EXPECT_EQ(a.framesUsed, 5);
    EXPECT_EQ(a.framesHealthy, 6);
    ASSERT_EQ(a.dropped.size(), 1u);
    EXPECT_EQ(a.dropped[0].flag, "disturbed");
    EXPECT_NE(a.dropped[0].reason.find("frame 1"), std::string::npos) << a.dropped[0].reason;
    // The average is that of frames 2..6.
    cv::Mat expected = cv::Mat::zeros(truth.size(), CV_32F);
    for (int i = 1; i < 6; ++i) cv::accumulate(frames[i], expected);
    expected /= 5.0;
    EXPECT_LT(cv::norm(a.frame, expected, cv::NORM_INF), 1e-3);
}

TEST(CaptureAverage, FramesAddedOneByOneGiveTheSameAverageAndTheAccumulatorStartsAfresh) {
    const cv::Mat truth = scene();
    std::vector<cv::Mat> frames;
    for (int i = 0; i < 5; ++i) frames.push_back(noisyFrame(truth, 2.0, 500 + i));
    frames[3] = noisyFrame(scene(1.5), 2.0, 600);  // moved
    const AveragedCapture all = averageCapture(frames, {}, lenient());
    CaptureAccumulator accumulator(lenient());
    for (int round = 0; round < 2; ++round) {
        for (const cv::Mat& f : frames) accumulator.add(f);
        EXPECT_EQ(accumulator.framesAdded(), 5);
        const AveragedCapture one = accumulator.finish();
        EXPECT_EQ(accumulator.framesAdded(), 0);
        EXPECT_EQ(one.framesUsed, 4);
        EXPECT_EQ(cv::norm(one.frame, all.frame, cv::NORM_INF), 0.0);
        ASSERT_EQ(one.dropped.size(), 1u);
        EXPECT_EQ(one.dropped[0].flag, "moved");
        EXPECT_NE(one.dropped[0].reason.find("frame 4"), std::string::npos) << one.dropped[0].reason;
    }
}

TEST(CaptureAverage, TooFewUsableFramesIsNoCaptureAndSaysWhy) {
    std::vector<cv::Mat> frames{noisyFrame(scene(), 2.0, 1) / 20, noisyFrame(scene(), 2.0, 2) / 20};
    CaptureAverageOptions o = lenient();
    o.minFrames = 1;
    const AveragedCapture a = averageCapture(frames, {}, o);
    EXPECT_TRUE(a.frame.empty());
    EXPECT_NE(a.reason.find("0 usable frames of 2"), std::string::npos) << a.reason;
}

// A burst under one fault drops every frame alike: the reason names the first in full and counts
// the rest, so that it stays one readable line however long the burst.
TEST(CaptureAverage, FramesDroppedForTheSameCauseAreCountedNotListed) {
    std::vector<cv::Mat> frames;
    std::vector<std::string> names;
    for (int k = 1; k <= 6; ++k) {
        frames.push_back(noisyFrame(scene(), 2.0, k) / 20);
        names.push_back("00000" + std::to_string(k) + ".jpg");
    }
    CaptureAverageOptions o = lenient();
    o.minFrames = 1;
    const AveragedCapture a = averageCapture(frames, names, o);
    ASSERT_TRUE(a.frame.empty());
    ASSERT_EQ(a.dropped.size(), 6u);
    EXPECT_NE(a.reason.find("0 usable frames of 6"), std::string::npos) << a.reason;
    EXPECT_NE(a.reason.find("000001.jpg: "), std::string::npos) << a.reason;
    EXPECT_EQ(a.reason.find("000002.jpg"), std::string::npos) << a.reason;
    EXPECT_NE(a.reason.find("(and 5 more frames: " + a.dropped[0].flag + ")"), std::string::npos) << a.reason;
}

TEST(CaptureAverage, AFrameOfAnotherSizeIsAnError) {
    std::vector<cv::Mat> frames{noisyFrame(scene(), 2.0, 1), cv::Mat(100, 100, CV_8U, cv::Scalar(90))};
    EXPECT_THROW(averageCapture(frames, {"a.jpg", "b.jpg"}, lenient()), InvalidInput);
}

}  // namespace
}  // namespace icewatch::volume
