// Texture along the image rows where the ice was read.
#include "core/volume/row_texture.hpp"

#include <cmath>
#include <limits>
#include <random>

#include <gtest/gtest.h>

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

TEST(RowTexture, IceIsFaintWhereItsRowsCarryNoTexture) {
    const cv::Mat image = shadedImage(2.0, 100, 0.5);
    cv::Mat thickness(image.size(), CV_32F, cv::Scalar(std::numeric_limits<float>::quiet_NaN()));
    thickness(cv::Rect(20, 20, 160, 80)).setTo(5.0f);   // ice read over both halves
    thickness(cv::Rect(20, 100, 160, 10)).setTo(0.2f);  // too thin to count
    const RowTextureOptions options;
    const FaintIce half = faintIce(image, thickness, options);
    EXPECT_EQ(half.icePixels, 160 * 80);
    EXPECT_NEAR(half.share(), 0.5, 0.06);  // the window straddles the texture's end by its radius
    EXPECT_TRUE(half.unmeasured(options));

    const FaintIce textured = faintIce(shadedImage(2.0, 200, 0.5), thickness, options);
    EXPECT_EQ(textured.faintPixels, 0);
    EXPECT_FALSE(textured.unmeasured(options));

    // Too few ice pixels are not judged.
    cv::Mat speck(image.size(), CV_32F, cv::Scalar(std::numeric_limits<float>::quiet_NaN()));
    speck(cv::Rect(150, 50, 10, 10)).setTo(5.0f);
    const FaintIce few = faintIce(image, speck, options);
    EXPECT_EQ(few.share(), 1.0);
    EXPECT_FALSE(few.unmeasured(options));
}

}  // namespace
}  // namespace icewatch::volume
