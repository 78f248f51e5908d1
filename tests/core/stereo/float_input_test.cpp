// Float input, the average of N frames: matched on its rounding to 8 bits except for the sub-pixel
// intensity refinement, which reads the float itself. An 8-bit image passed as float changes
// nothing; a real average keeps the sub-pixel information its rounding throws away.
#include <cstring>
#include <limits>

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "core/common/error.hpp"
#include "core/stereo/matcher.hpp"
#include "tests/core/stereo/stereo_test_images.hpp"

namespace icewatch::stereo {
namespace {

cv::Mat asFloat(const cv::Mat& image) {
    cv::Mat out;
    image.convertTo(out, CV_32F);
    return out;
}

bool bitIdentical(const cv::Mat& a, const cv::Mat& b) {
    return a.size() == b.size() && a.type() == b.type() &&
           std::equal(a.begin<float>(), a.end<float>(), b.begin<float>(), [](float x, float y) {
               return std::memcmp(&x, &y, sizeof x) == 0;
           });
}

// A grey pair at 8 bits whose right eye sees the texture 6.4 px to the left, with what the
// cleaning stages act on: added noise (the smoothing starts) and impulses (the repair starts).
void greyPair(double noiseSigma, bool impulses, cv::Mat& left, cv::Mat& right) {
    const cv::Mat texture = test::randomImage(151, 63, CV_8UC1, 31);
    const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, 6.4, 0, 1, 0);
    left = texture;
    cv::warpAffine(texture, right, shift, texture.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
    cv::RNG rng(5);
    for (cv::Mat* eye : {&left, &right}) {
        cv::Mat noisy;
        eye->convertTo(noisy, CV_32F);
        cv::Mat noise(noisy.size(), CV_32F);
        rng.fill(noise, cv::RNG::NORMAL, 0.0, noiseSigma);
        noisy += noise;
        noisy.convertTo(*eye, CV_8U);
        if (impulses)
            for (int i = 0; i < 40; ++i) eye->at<std::uint8_t>(rng.uniform(0, eye->rows), rng.uniform(0, eye->cols)) = 255;
    }
}

TEST(FloatInput, EightBitImagesAsFloatGiveTheSameDisparitiesBitForBit) {
    struct Case {
        double noise;
        bool impulses;
    };
    for (const Case c : {Case{0.0, false}, Case{0.0, true}, Case{4.0, false}, Case{4.0, true}}) {
        cv::Mat left, right;
        greyPair(c.noise, c.impulses, left, right);
        for (const Method method : {Method::Paper, Method::AdCensus, Method::Sgbm}) {
            Matcher eightBit(method), asFloatInput(method);
            const cv::Mat expected = eightBit.compute(left, right, DisparityRange{2, 20});
            const cv::Mat actual = asFloatInput.compute(asFloat(left), asFloat(right), DisparityRange{2, 20});
            EXPECT_TRUE(bitIdentical(expected, actual))
                << methodName(method) << ", noise " << c.noise << ", impulses " << c.impulses;
        }
    }
}

TEST(FloatInput, RejectsFloatImagesThatAreNotFinite) {
    Matcher matcher(Method::Paper);
    cv::Mat a(10, 20, CV_32FC1, cv::Scalar(100.0f));
    cv::Mat b = a.clone();
    b.at<float>(3, 4) = std::numeric_limits<float>::quiet_NaN();
    EXPECT_THROW(matcher.compute(a, b, 8), InvalidInput);
    EXPECT_THROW(matcher.compute(a, cv::Mat(10, 20, CV_8UC1, cv::Scalar(1)), 8), InvalidInput);  // types differ
    EXPECT_THROW(matcher.compute(cv::Mat(10, 20, CV_32FC3), cv::Mat(10, 20, CV_32FC3), 8), InvalidInput);
}

// A weakly textured surface (grey 100 .. 140, a few grey levels of contrast between neighbours)
// seen 5.3 px apart, rendered 8x finer and area-averaged; 16 frames per eye, each with its own
// Gaussian noise of sigma 0.8, averaged in float: 0.2 grey levels of noise left. Rounding that
// average to 8 bits adds 0.29 more (a uniform error of one step), which the float does not have.
// Measured over noise seeds 3-6: 0.081-0.087 px RMS from the float, 0.129-0.135 px from its
// rounding (ratio 0.62-0.67).
TEST(FloatInput, TheFloatAverageOfSixteenFramesBeatsItsRoundingToEightBits) {
    constexpr int kFine = 8, kWidth = 160, kHeight = 64, kFrames = 16;
    constexpr double kShift = 5.3, kNoise = 0.8;
    cv::Mat fine = test::randomImage((kWidth + 32) / 2, kHeight / 2, CV_8UC1, 17);
    fine.convertTo(fine, CV_32F, 40.0 / 255.0, 100.0);
    cv::resize(fine, fine, {(kWidth + 32) * kFine, kHeight * kFine}, 0, 0, cv::INTER_CUBIC);
    const int margin = 16 * kFine;
    const int shift = static_cast<int>(std::lround(kShift * kFine));
    cv::Mat cleanLeft, cleanRight;
    cv::resize(fine(cv::Rect(margin, 0, kWidth * kFine, kHeight * kFine)), cleanLeft, {kWidth, kHeight}, 0, 0,
               cv::INTER_AREA);
    cv::resize(fine(cv::Rect(margin + shift, 0, kWidth * kFine, kHeight * kFine)), cleanRight, {kWidth, kHeight}, 0,
               0, cv::INTER_AREA);
    const double truth = static_cast<double>(shift) / kFine;

    cv::RNG rng(3);
    auto average = [&](const cv::Mat& clean) {
        cv::Mat sum(clean.size(), CV_32F, cv::Scalar(0.0f)), noise(clean.size(), CV_32F);
        for (int i = 0; i < kFrames; ++i) {
            rng.fill(noise, cv::RNG::NORMAL, 0.0, kNoise);
            sum += clean + noise;
        }
        return cv::Mat(sum / kFrames);
    };
    const cv::Mat left = average(cleanLeft), right = average(cleanRight);
    cv::Mat left8, right8;
    left.convertTo(left8, CV_8U);
    right.convertTo(right8, CV_8U);

    Matcher matcher(Method::Paper);
    const cv::Mat fromFloat = matcher.compute(left, right, DisparityRange{0, 16});
    const cv::Mat fromRounded = matcher.compute(left8, right8, DisparityRange{0, 16});
    // RMS error over the pixels both got right to within a pixel, away from the borders.
    double floatSum = 0.0, roundedSum = 0.0;
    int count = 0;
    for (int y = 6; y < kHeight - 6; ++y)
        for (int x = 24; x < kWidth - 6; ++x) {
            const double a = fromFloat.at<float>(y, x) - truth, b = fromRounded.at<float>(y, x) - truth;
            if (std::abs(a) >= 1.0 || std::abs(b) >= 1.0) continue;
            floatSum += a * a;
            roundedSum += b * b;
            ++count;
        }
    ASSERT_GT(count, (kHeight - 12) * (kWidth - 30) * 9 / 10);
    const double floatRms = std::sqrt(floatSum / count), roundedRms = std::sqrt(roundedSum / count);
    EXPECT_LT(floatRms, 0.75 * roundedRms) << "float " << floatRms << " px, rounded " << roundedRms << " px";
}

}  // namespace
}  // namespace icewatch::stereo
