// Texture along the image rows where the ice was read.
#include "core/volume/row_texture.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

namespace icewatch::volume {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A grey image: shading across the rows (a bead's, brightest in its middle), a texture along the
// rows of amplitude `rowAmplitude` (grey levels) left of `textureEndsAt`, and noise σ `noise`.
cv::Mat shadedImage(double rowAmplitude, int textureEndsAt, double noise, unsigned seed = 7) {
    cv::Mat image(120, 200, CV_32F);
    std::mt19937 random(seed);
    std::normal_distribution<double> gauss(0.0, noise);
    for (int y = 0; y < image.rows; ++y)
        for (int x = 0; x < image.cols; ++x) {
            const double across = 120.0 + 40.0 * std::cos(kPi * (y - 60) / 120.0);
            const double along = x < textureEndsAt ? rowAmplitude * std::sin(2.0 * kPi * x / 9.0) : 0.0;
            image.at<float>(y, x) = static_cast<float>(across + along + gauss(random));
        }
    return image;
}

TEST(RowTexture, TheNoiseEstimateIgnoresSmoothShadingAndFindsTheNoise) {
    const cv::Mat image = shadedImage(0.0, 0, 0.8);
    const cv::Mat all(image.size(), CV_8U, cv::Scalar(255));
    EXPECT_NEAR(imageNoiseGrey(image, all), 0.8, 0.08);
    EXPECT_NEAR(imageNoiseGrey(shadedImage(0.0, 0, 0.0), all), 0.0, 0.05);
    EXPECT_EQ(imageNoiseGrey(image, cv::Mat(image.size(), CV_8U, cv::Scalar(0))), 0.0);
}

// The edges of ice or of the object answer the noise operator too; on a fifth of the image they
// must not raise the noise the texture is judged against (their mean made it 2.7 times too high).
TEST(RowTexture, TheNoiseEstimateIsNotRaisedByStrongTextureOnPartOfTheImage) {
    cv::Mat image = shadedImage(0.0, 0, 0.8);
    for (int y = 0; y < image.rows; ++y)
        for (int x = 0; x < 40; ++x)  // a fifth of the image: a rough, bright horn's texture
            image.at<float>(y, x) += static_cast<float>(15.0 * std::sin(2.0 * kPi * x / 5.0) * std::cos(2.0 * kPi * y / 7.0));
    const cv::Mat all(image.size(), CV_8U, cv::Scalar(255));
    EXPECT_NEAR(imageNoiseGrey(image, all), 0.8, 0.12);
}

TEST(RowTexture, ShadingAcrossTheRowsIsNoTextureAndASineAlongThemIs) {
    const double amplitude = 2.0;
    const cv::Mat image = shadedImage(amplitude, 100, 0.5);
    const cv::Mat texture = rowTextureGreyPerPx(image, 0.5, 6);
    // The central difference of A·sin(2πx/9) has rms A·sin(2π/9)/√2.
    const double expected = amplitude * std::sin(2.0 * kPi / 9.0) / std::sqrt(2.0);
    EXPECT_NEAR(texture.at<float>(60, 50), expected, 0.15 * expected);
    // Where only the shading across the rows and the noise are, nothing is left.
    EXPECT_LT(texture.at<float>(60, 160), 0.15);
    EXPECT_LT(texture.at<float>(20, 160), 0.15);
}


// JPEG-like noise: white noise with its finest frequencies taken away, which the image's second
// differences miss and the horizontal difference does not.
cv::Mat smoothedNoise(cv::Size size, double sigma, std::uint64_t seed) {
    cv::Mat noise(size, CV_32F);
    cv::RNG(seed).fill(noise, cv::RNG::NORMAL, 0.0, sigma);
    cv::GaussianBlur(noise, noise, {0, 0}, 0.8);
    return noise;
}

TEST(RowTexture, ANoiseDrawTakesOffTheNoiseTheImagesSecondDifferencesMiss) {
    const double amplitude = 1.0;
    const cv::Mat clean = shadedImage(amplitude, 100, 0.0);
    const cv::Mat image = clean + smoothedNoise(clean.size(), 3.0, 1);
    const cv::Mat draw = smoothedNoise(clean.size(), 3.0, 2);  // the same noise, another draw
    const cv::Mat all(image.size(), CV_8U, cv::Scalar(255));
    const cv::Mat byDraw = rowTextureGreyPerPx(image, rowNoisePower(draw, 6), 6);
    const cv::Mat byImage = rowTextureGreyPerPx(image, imageNoiseGrey(image, all), 6);
    const double expected = amplitude * std::sin(2.0 * kPi / 9.0) / std::sqrt(2.0);
    auto median = [](const cv::Mat& texture, int x0, int x1) {
        std::vector<float> v;
        for (int y = 10; y < texture.rows - 10; ++y)
            for (int x = x0; x < x1; ++x) v.push_back(texture.at<float>(y, x));
        std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
        return double(v[v.size() / 2]);
    };
    // Where the noise is all, the draw leaves little; the image's own estimate leaves most of it,
    // more than the texture beside it.
    EXPECT_LT(median(byDraw, 120, 190), 0.5 * expected);
    EXPECT_GT(median(byImage, 120, 190), expected);
    // The texture is still found beside it.
    EXPECT_NEAR(median(byDraw, 10, 90), expected, 0.35 * expected);
}
cv::Mat noThickness(cv::Size size) { return {size, CV_32F, cv::Scalar(std::numeric_limits<float>::quiet_NaN())}; }

RowTextureInputs unmoved(const cv::Mat& baseline, const cv::Mat& current, const cv::Mat& thickness) {
    cv::Mat object = cv::Mat::zeros(baseline.size(), CV_8U);
    object(cv::Rect(20, 20, 160, 80)).setTo(255);
    return {baseline, current, {}, {}, object, [](cv::Point2d px) { return px; }, 1.0, thickness, {}};
}

TEST(RowTexture, IceReadWhereItsRowsCarryNoTextureIsFaint) {
    const cv::Mat image = shadedImage(2.0, 100, 0.5);
    cv::Mat thickness = noThickness(image.size());
    thickness(cv::Rect(20, 20, 160, 80)).setTo(5.0f);   // ice read over both halves
    thickness(cv::Rect(20, 100, 160, 10)).setTo(0.2f);  // too thin to count
    const RowTextureOptions options;
    // The baseline as plain as the current capture: nothing was lost, the ice read is judged.
    const FaintIce half = faintIce(unmoved(image, image, thickness), options);
    EXPECT_EQ(half.icePixels, 160 * 80);
    EXPECT_EQ(half.lostPixels, 0);
    EXPECT_NEAR(half.share(), 0.5, 0.06);  // the window straddles the texture's end by its radius
    EXPECT_TRUE(half.unmeasured(options));

    const cv::Mat textured = shadedImage(2.0, 200, 0.5);
    const FaintIce measured = faintIce(unmoved(textured, textured, thickness), options);
    EXPECT_EQ(measured.faintPixels, 0);
    EXPECT_FALSE(measured.unmeasured(options));

    // Too few ice pixels are not judged.
    cv::Mat speck = noThickness(image.size());
    speck(cv::Rect(150, 50, 10, 10)).setTo(5.0f);
    const FaintIce few = faintIce(unmoved(image, image, speck), options);
    EXPECT_EQ(few.share(), 1.0);
    EXPECT_FALSE(few.unmeasured(options));
}

// Ice the matcher read flat (no thickness at all) still shows where the object's texture went.
TEST(RowTexture, TextureLostWhereNoIceWasReadIsFaintIce) {
    const cv::Mat baseline = shadedImage(2.0, 200, 0.5, 7);
    const cv::Mat current = shadedImage(2.0, 100, 0.5, 8);  // the right half's texture covered
    const RowTextureOptions options;
    const FaintIce flat = faintIce(unmoved(baseline, current, noThickness(baseline.size())), options);
    EXPECT_NEAR(flat.lostPixels, 80 * 80, 80 * 8);
    EXPECT_EQ(flat.faintPixels, flat.icePixels);
    EXPECT_TRUE(flat.unmeasured(options));

    // Where the object moved, its texture is looked for where it went.
    RowTextureInputs moved = unmoved(baseline, current, noThickness(baseline.size()));
    cv::Mat shifted;
    const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, 3, 0, 1, 2);
    cv::warpAffine(shadedImage(2.0, 200, 0.5, 8), shifted, shift, baseline.size(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
    moved.currentGrey = shifted;
    moved.toCurrent = [](cv::Point2d px) { return px + cv::Point2d(3, 2); };
    EXPECT_EQ(faintIce(moved, options).lostPixels, 0);

    // Light that dimmed is not texture lost: half the light leaves half the texture.
    RowTextureInputs dimmed = unmoved(shadedImage(1.0, 200, 0.3, 7), cv::Mat(), noThickness(baseline.size()));
    dimmed.currentGrey = 0.5 * shadedImage(1.0, 200, 0.0, 8);
    dimmed.lightRatio = 0.5;
    const FaintIce dim = faintIce(dimmed, options);
    EXPECT_EQ(dim.lostPixels, 0);
}

// Where stereo could not read what hid the texture (lost_texture.hpp) and no ice was read, the
// ice is lost whatever the rows' texture seems to be: a single frame's noise passes for texture.
// Where ice was read, something placed it, and its rows are judged as anywhere.
TEST(RowTexture, WhatStereoCouldNotReadWhereTheTextureWentAndNoIceWasReadIsLost) {
    const cv::Mat image = shadedImage(2.0, 200, 0.5, 7);  // texture along the rows everywhere
    const RowTextureOptions options;
    RowTextureInputs inputs = unmoved(image, image, noThickness(image.size()));
    EXPECT_EQ(faintIce(inputs, options).icePixels, 0);
    inputs.unreadLost = cv::Mat::zeros(image.size(), CV_8U);
    inputs.unreadLost(cv::Rect(40, 40, 60, 50)).setTo(255);
    inputs.thicknessMm(cv::Rect(40, 40, 60, 50)).setTo(0.5f);  // read, but thinner than ice counts
    const FaintIce unread = faintIce(inputs, options);
    EXPECT_EQ(unread.lostPixels, 60 * 50);
    EXPECT_EQ(unread.faintPixels, 60 * 50);
    EXPECT_EQ(unread.icePixels, 60 * 50);
    EXPECT_TRUE(unread.unmeasured(options));

    inputs.thicknessMm(cv::Rect(40, 40, 30, 50)).setTo(50.0f);  // a block's top, carried from its edges
    const FaintIce placed = faintIce(inputs, options);
    EXPECT_EQ(placed.lostPixels, 30 * 50);
    EXPECT_EQ(placed.icePixels, 60 * 50);
    EXPECT_EQ(placed.faintPixels, 30 * 50);  // the rows there carry texture
}

// A registration gone wild places the object nowhere or far off the image: nothing there is
// counted, and nothing is read outside the image.
TEST(RowTexture, PlacesOffTheImageOrNotANumberAreNotLookedAt) {
    const cv::Mat baseline = shadedImage(2.0, 200, 0.5, 7);
    const cv::Mat current = shadedImage(2.0, 100, 0.5, 8);
    const RowTextureOptions options;
    for (const double far : {1e30, -1e30, 1e12, std::numeric_limits<double>::quiet_NaN(),
                             std::numeric_limits<double>::infinity(), -0.5, 200.5}) {
        RowTextureInputs lost = unmoved(baseline, current, noThickness(baseline.size()));
        lost.toCurrent = [far](cv::Point2d px) { return cv::Point2d(far, px.y); };
        EXPECT_EQ(faintIce(lost, options).lostPixels, 0) << far;
        lost.toCurrent = [far](cv::Point2d px) { return cv::Point2d(px.x, far); };
        EXPECT_EQ(faintIce(lost, options).lostPixels, 0) << far;
    }
}

}  // namespace
}  // namespace icewatch::volume
