#include "core/volume/drawn_outline.hpp"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

namespace icewatch::volume {
namespace {

constexpr double kMinTextureGrey = 1.0;
constexpr double kMinContrastGrey = 3.0;

// A weakly textured object (grey 150, a 3-level pattern) on a uniform sky (grey 200), both with
// the noise an averaged capture keeps (0.4 levels), the object a slanted bar like a blade.
struct Picture {
    cv::Mat grey;    // CV_32F
    cv::Mat object;  // CV_8U, the truth
};

Picture bladeAgainstSky(float skyGrey = 200.0f, bool texturedBackground = false) {
    Picture p;
    p.object = cv::Mat::zeros(240, 400, CV_8U);
    const std::vector<cv::Point> bar{{60, 100}, {340, 80}, {345, 130}, {55, 150}};
    cv::fillConvexPoly(p.object, bar, cv::Scalar(255));
    p.grey.create(p.object.size(), CV_32F);
    cv::RNG rng(7);
    cv::Mat table(p.object.size(), CV_32F);
    rng.fill(table, cv::RNG::NORMAL, 0.0, 12.0);
    cv::GaussianBlur(table, table, {0, 0}, 1.5);
    for (int y = 0; y < p.grey.rows; ++y)
        for (int x = 0; x < p.grey.cols; ++x) {
            const bool on = p.object.at<std::uint8_t>(y, x) != 0;
            const float pattern = 3.0f * std::sin(0.7f * x) * std::cos(0.5f * y);
            const float background = texturedBackground ? 110.0f + table.at<float>(y, x) : skyGrey;
            p.grey.at<float>(y, x) = (on ? 150.0f + pattern : background) + static_cast<float>(rng.gaussian(0.4));
        }
    return p;
}

cv::Mat grown(const cv::Mat& mask, int px) {
    cv::Mat out;
    cv::dilate(mask, out, cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * px + 1, 2 * px + 1}));
    return out;
}

int differing(const cv::Mat& a, const cv::Mat& b) { return cv::countNonZero(a != b); }

TEST(DrawnOutline, AnOutlineDrawnWideOfTheObjectAgainstTheSkyComesBackToItsEdge) {
    const Picture p = bladeAgainstSky();
    const cv::Mat drawn = grown(p.object, 20);
    const DrawnOutline out = objectInDrawnOutline(drawn, p.grey, kMinTextureGrey, kMinContrastGrey);
    // Every pixel of the margin but the edge's own: its perimeter is about 640 px.
    EXPECT_LT(differing(out.object, p.object), 100) << "of " << cv::countNonZero(drawn - p.object) << " in the margin";
    EXPECT_EQ(cv::countNonZero(out.object & ~drawn), 0) << "nothing is added to what was drawn";
    EXPECT_NEAR(out.backgroundPercent, 100.0 * cv::countNonZero(drawn - p.object) / cv::countNonZero(drawn), 1.0);
}

TEST(DrawnOutline, AnOutlineOnTheObjectsEdgeComesBackAsDrawn) {
    const Picture p = bladeAgainstSky();
    const DrawnOutline out = objectInDrawnOutline(p.object, p.grey, kMinTextureGrey, kMinContrastGrey);
    EXPECT_EQ(differing(out.object, p.object), 0);
    EXPECT_EQ(out.backgroundPercent, 0.0);
}

// Drawn across the object (its ends left out): the object's featureless parts outside the outline
// are not the background, and do not lead into the object inside it.
TEST(DrawnOutline, AnOutlineCuttingAcrossTheObjectKeepsTheObjectInside) {
    Picture p = bladeAgainstSky();
    // The object without texture, so that its parts outside the outline are as featureless as the sky.
    cv::Mat plain(p.grey.size(), CV_32F);
    cv::RNG rng(3);
    rng.fill(plain, cv::RNG::NORMAL, 0.0, 0.4);
    plain += 150.0f;
    plain.copyTo(p.grey, p.object);
    cv::Mat drawn = grown(p.object, 15);
    drawn.colRange(0, 120).setTo(0);
    drawn.colRange(300, drawn.cols).setTo(0);
    const DrawnOutline out = objectInDrawnOutline(drawn, p.grey, kMinTextureGrey, kMinContrastGrey);
    EXPECT_LT(differing(out.object, p.object & drawn), 40);
}

// Drawn over a textured background (a table), the outline comes back as drawn: the chain
// measures a table as the clean surface it is.
TEST(DrawnOutline, AnOutlineDrawnOverATexturedBackgroundComesBackAsDrawn) {
    const Picture p = bladeAgainstSky(200.0f, true);
    const cv::Mat drawn = grown(p.object, 20);
    const DrawnOutline out = objectInDrawnOutline(drawn, p.grey, kMinTextureGrey, kMinContrastGrey);
    EXPECT_EQ(differing(out.object, drawn), 0);
    EXPECT_EQ(out.backgroundPercent, 0.0);
}

// Where no picture was taken (grey 0, outside the matched window) is neither object nor background.
TEST(DrawnOutline, PixelsWithoutAPictureAreNotBackground) {
    Picture p = bladeAgainstSky();
    const cv::Mat drawn = grown(p.object, 20);
    p.grey.rowRange(0, 70).setTo(0.0f);
    const DrawnOutline out = objectInDrawnOutline(drawn, p.grey, kMinTextureGrey, kMinContrastGrey);
    EXPECT_LT(differing(out.object.rowRange(70, p.grey.rows), p.object.rowRange(70, p.grey.rows)), 100);
    EXPECT_EQ(differing(out.object.rowRange(0, 70), drawn.rowRange(0, 70)), 0) << "kept as drawn";
}

}  // namespace
}  // namespace icewatch::volume
