#include "core/volume/roi.hpp"

#include <cmath>
#include <functional>
#include <limits>

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

namespace icewatch::volume {
namespace {

constexpr double kDepthMm = 850.0;
constexpr double kBandMm = 150.0;
constexpr double kMinTextureGrey = 1.0;
constexpr double kMinContrastGrey = 3.0;

// A weakly textured bar like a blade (grey 150, a 3-level pattern) across a view whose every pixel
// the matcher placed at the bar's depth, as it fills a featureless sky; the background is a uniform
// sky (grey 200) or a textured table. Both keep an averaged capture's noise (0.4 levels). The view
// is pictured but for a black margin, as a rectified eye leaves one.
struct View {
    cv::Mat grey;    // CV_32F, 0 where nothing was pictured
    cv::Mat points;  // CV_32FC3, every pictured pixel at kDepthMm
    cv::Mat object;  // CV_8U, the truth
};

View barInView(bool texturedBackground) {
    View v;
    const cv::Size size(480, 300);
    v.object = cv::Mat::zeros(size, CV_8U);
    const std::vector<cv::Point> bar{{70, 130}, {400, 105}, {405, 160}, {65, 185}};
    cv::fillConvexPoly(v.object, bar, cv::Scalar(255));
    cv::RNG rng(11);
    cv::Mat table(size, CV_32F);
    rng.fill(table, cv::RNG::NORMAL, 0.0, 12.0);
    cv::GaussianBlur(table, table, {0, 0}, 1.5);
    v.grey = cv::Mat::zeros(size, CV_32F);
    v.points = cv::Mat(size, CV_32FC3, cv::Scalar::all(std::numeric_limits<float>::quiet_NaN()));
    const cv::Rect pictured(6, 4, size.width - 12, size.height - 8);
    for (int y = pictured.y; y < pictured.br().y; ++y)
        for (int x = pictured.x; x < pictured.br().x; ++x) {
            const bool on = v.object.at<std::uint8_t>(y, x) != 0;
            const float pattern = 3.0f * std::sin(0.7f * x) * std::cos(0.5f * y);
            const float background = texturedBackground ? 110.0f + table.at<float>(y, x) : 200.0f;
            v.grey.at<float>(y, x) = (on ? 150.0f + pattern : background) + static_cast<float>(rng.gaussian(0.4));
            v.points.at<cv::Vec3f>(y, x) = cv::Vec3f(0.0f, 0.0f, static_cast<float>(kDepthMm));
        }
    return v;
}

TEST(SegmentObject, AgainstTheSkyTheSkyTheMatcherFilledIsLeftOutUpToTheObjectsEdge) {
    const View v = barInView(false);
    ASSERT_GT(cv::countNonZero(segmentRoi(v.points, kBandMm)), 0.9 * cv::countNonZero(v.grey > 0.0f))
        << "depth alone finds the view";
    const cv::Mat found = segmentObject(v.points, v.grey, kBandMm, kMinTextureGrey, kMinContrastGrey);
    // The edge's own pixels may go either way: the bar's perimeter is about 780 px.
    EXPECT_LT(cv::countNonZero(found != v.object), 160) << "of " << cv::countNonZero(v.object) << " on the bar";
}

TEST(SegmentObject, OverATexturedBackgroundItIsTheRegionAtTheObjectsDepth) {
    const View v = barInView(true);
    const cv::Mat found = segmentObject(v.points, v.grey, kBandMm, kMinTextureGrey, kMinContrastGrey);
    // A table at the object's depth is no sky: the view stays, and the chain's gate refuses it.
    EXPECT_EQ(cv::countNonZero(found != segmentRoi(v.points, kBandMm)), 0);
}

// The bar's view with every pixel's depth set by `depthMm(x, y, onBar)`.
void placeDepths(View& v, const std::function<double(int, int, bool)>& depthMm) {
    for (int y = 0; y < v.points.rows; ++y)
        for (int x = 0; x < v.points.cols; ++x) {
            cv::Vec3f& p = v.points.at<cv::Vec3f>(y, x);
            if (std::isnan(p[2])) continue;
            p[2] = static_cast<float>(depthMm(x, y, v.object.at<std::uint8_t>(y, x) != 0));
        }
}

TEST(SegmentObject, ABandCutOutOfATexturedSurfaceItLiesOnIsTheView) {
    // A table bent away from the view, deeper by the square of the distance from its middle row,
    // so that the band about its plane cuts a strip out of it.
    View v = barInView(true);
    placeDepths(v, [](int, int y, bool) { return kDepthMm + 0.02 * (y - 150) * (y - 150); });
    const cv::Mat atDepth = segmentRoi(v.points, kBandMm);
    ASSERT_LT(frameEdgeShare(atDepth), 0.6) << "the strip alone passes for an object";
    const cv::Mat found = segmentObject(v.points, v.grey, kBandMm, kMinTextureGrey, kMinContrastGrey);
    EXPECT_EQ(cv::countNonZero(found), found.rows * found.cols) << "the whole view, for the region gate";
}

TEST(SegmentObject, AnObjectBeforeATexturedBackgroundFarBehindItIsItsDepthsRegion) {
    // Ground receding behind it, from 600 mm beyond it: the bar is the dominant depth.
    View v = barInView(true);
    placeDepths(v, [](int, int y, bool onBar) { return onBar ? kDepthMm : kDepthMm + 600.0 + 20.0 * y; });
    const cv::Mat found = segmentObject(v.points, v.grey, kBandMm, kMinTextureGrey, kMinContrastGrey);
    // The region's opening rounds the bar's corners.
    EXPECT_LT(cv::countNonZero(found != v.object), 80) << "of " << cv::countNonZero(v.object) << " on the bar";
}

TEST(SegmentObject, AnObjectTurnedOutOfTheViewKeepsTheEndsOneDepthsBandCutsOff) {
    // The bar swung about the vertical, a plane (its inverse depth affine in the pixel) from 650 mm
    // to 1150 mm deep end to end, with the sky the matcher filled at the bar's depth in each column.
    View v = barInView(false);
    placeDepths(v, [](int x, int, bool) { return 1.0 / (1.0 / kDepthMm - 1.97e-6 * (x - 235)); });
    const cv::Mat found = segmentObject(v.points, v.grey, kBandMm, kMinTextureGrey, kMinContrastGrey);
    EXPECT_LT(cv::countNonZero(v.object & ~found), 100) << "of " << cv::countNonZero(v.object) << " on the bar";
    EXPECT_LT(cv::countNonZero(found & ~v.object), 100);
}

TEST(SegmentObject, NothingAtAnyDepthIsNoRegion) {
    View v = barInView(false);
    v.points.setTo(cv::Scalar::all(std::numeric_limits<float>::quiet_NaN()));
    EXPECT_EQ(cv::countNonZero(segmentObject(v.points, v.grey, kBandMm, kMinTextureGrey, kMinContrastGrey)), 0);
}

}  // namespace
}  // namespace icewatch::volume
