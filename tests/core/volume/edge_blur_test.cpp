// How blurred a capture is, read off the object's outline.
#include "core/volume/edge_blur.hpp"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

namespace icewatch::volume {
namespace {

// A band (rows top to bottom) darker than its background, textured as a blade and a table are, drawn at 4x and reduced
// by area (the pixels' own box), then blurred by `sigmaPx` and given a little noise.
cv::Mat bandImage(double sigmaPx, cv::Mat* roi, double top = 100.4, double bottom = 140.4) {
    const int w = 400, h = 240, s = 4;
    cv::Mat fine(h * s, w * s, CV_32F);
    for (int y = 0; y < fine.rows; ++y)
        for (int x = 0; x < fine.cols; ++x) {
            const double u = x / double(s), v = y / double(s);
            const bool band = u >= 60.3 && u < 340.3 && v >= top && v < bottom;
            const double table = 110.0 + 8.0 * std::sin(0.9 * u + 0.4 * v);
            const double blade = 160.0 + 4.0 * std::sin(0.35 * u) * std::sin(0.3 * v);
            fine.at<float>(y, x) = static_cast<float>(band ? blade : table);
        }
    cv::Mat image;
    cv::resize(fine, image, {w, h}, 0, 0, cv::INTER_AREA);
    if (sigmaPx > 0) cv::GaussianBlur(image, image, {0, 0}, sigmaPx);
    std::mt19937 random(3);
    std::normal_distribution<float> noise(0.0f, 0.4f);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) image.at<float>(y, x) += noise(random);
    *roi = cv::Mat::zeros(h, w, CV_8U);
    const int y0 = static_cast<int>(top), y1 = static_cast<int>(bottom);
    (*roi)(cv::Rect(60, y0, 281, y1 - y0 + 1)).setTo(255);
    return image;
}

TEST(EdgeBlur, TheOutlinesSpreadIsTheLenssBlur) {
    cv::Mat roi;
    const cv::Rect all(0, 0, 400, 240);
    const std::optional<double> sharp = outlineBlurPx(bandImage(0.0, &roi), roi, all);
    ASSERT_TRUE(sharp);
    // As sharp as the pixels: a step sampled at their centres rises over one or two of them, as
    // its place falls on the pixel grid (here 0.4 px into one).
    EXPECT_GT(*sharp, 0.3);
    EXPECT_LT(*sharp, 0.9);
    for (const double sigma : {1.0, 2.0, 3.0}) {
        const std::optional<double> blurred = outlineBlurPx(bandImage(sigma, &roi), roi, all);
        ASSERT_TRUE(blurred) << sigma;
        EXPECT_NEAR(*blurred, std::hypot(sigma, *sharp), 0.15 * sigma) << sigma;
    }
}

TEST(EdgeBlur, AnOutlineDrawnInsideTheObjectsEdgeReadsTheEdgeAroundIt) {
    // The band's outline drawn 14 px in from its long edges and 20 px from its ends (a plate's
    // outline kept off its rim): no step under it, the band's edge a little way out.
    cv::Mat roi;
    const cv::Rect all(0, 0, 400, 240);
    const cv::Mat image = bandImage(2.0, &roi, 70.4, 170.4);
    cv::Mat inside = cv::Mat::zeros(roi.size(), CV_8U);
    inside(cv::Rect(80, 84, 241, 73)).setTo(255);
    ASSERT_FALSE(outlineBlurPx(image, inside, all)) << "the outline stands on the band's own texture";
    const std::optional<double> edge = objectBlurPx(image, roi, all);
    const cv::Mat drawn = inside.clone();
    const std::optional<double> found = objectBlurPx(image, inside, all);
    EXPECT_EQ(cv::countNonZero(inside != drawn), 0) << "the outline itself stays as drawn";
    ASSERT_TRUE(edge);
    ASSERT_TRUE(found);
    EXPECT_NEAR(*found, *edge, 0.2);
    EXPECT_GT(*found, 1.7);
}

TEST(EdgeBlur, AnOutlineThatStandsOutOfNothingSaysNothing) {
    cv::Mat roi;
    cv::Mat flat(240, 400, CV_32F, cv::Scalar(150.0f));
    bandImage(0.0, &roi);
    EXPECT_FALSE(outlineBlurPx(flat, roi, cv::Rect(0, 0, 400, 240)));
}

}  // namespace
}  // namespace icewatch::volume
