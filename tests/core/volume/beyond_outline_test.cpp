// Ice beyond the outline: the ring around the outline, its textured pixels, and which rising parts
// of it are ice.
#include "core/volume/beyond_outline.hpp"

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

namespace icewatch::volume {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

TEST(BeyondOutline, GrowthIsTheMillimetresAtTheObjectsDepth) {
    Parameters p;
    p.outlineGrowthMm = 50;
    EXPECT_EQ(outlineGrowthPx(p, 763.0, 850.0), 45);  // 44.9 px, rounded up
    p.outlineGrowthMm = 0;
    EXPECT_EQ(outlineGrowthPx(p, 763.0, 850.0), 0);
}

TEST(BeyondOutline, RingSurroundsTheRegionAndLeavesItOut) {
    cv::Mat region = cv::Mat::zeros(100, 200, CV_8U);
    cv::rectangle(region, cv::Rect(50, 40, 100, 20), cv::Scalar(255), cv::FILLED);
    const cv::Mat ring = outlineRing(region, 10);
    EXPECT_EQ(cv::countNonZero(ring & region), 0);
    EXPECT_TRUE(ring.at<std::uint8_t>(35, 100));   // 5 px above the region
    EXPECT_TRUE(ring.at<std::uint8_t>(69, 100));   // 10 px below
    EXPECT_FALSE(ring.at<std::uint8_t>(71, 100));  // 12 px below
    EXPECT_TRUE(ring.at<std::uint8_t>(50, 41));
    EXPECT_FALSE(ring.at<std::uint8_t>(50, 38));
    EXPECT_EQ(cv::countNonZero(outlineRing(region, 0)), 0);
}

// Featureless sky with its own noise in each eye around a textured strip, and the matcher's
// disparity everywhere (it fills the sky with the object's): only the strip is a measurement.
TEST(BeyondOutline, MeasurableRingLeavesTheFeaturelessSkyOut) {
    cv::Mat region = cv::Mat::zeros(120, 200, CV_8U);
    cv::rectangle(region, cv::Rect(40, 50, 120, 20), cv::Scalar(255), cv::FILLED);
    const cv::Mat ring = outlineRing(region, 30);
    const int disparity = 10;
    // Ice just above the region, fixed to the surface: a random texture of a few pixels' grain.
    cv::Mat texture(region.rows, region.cols + disparity, CV_32F);
    cv::randn(texture, 0.0, 12.0);
    cv::GaussianBlur(texture, texture, {0, 0}, 1.2);
    texture *= 3.0;
    auto strip = [&](int x, int y) {
        return y >= 36 && y < 50 && x >= 60 && x < 140 ? static_cast<double>(texture.at<float>(y, x)) : 0.0;
    };
    std::mt19937 random(3);
    std::normal_distribution<float> noise(0.0f, 0.8f);
    cv::Mat left(region.size(), CV_32F), right(region.size(), CV_32F);
    for (int y = 0; y < left.rows; ++y)
        for (int x = 0; x < left.cols; ++x) {
            left.at<float>(y, x) = static_cast<float>(200.0 + strip(x, y)) + noise(random);
            const int seen = x + disparity;  // the right eye sees the surface point x + d at x
            right.at<float>(y, x) = static_cast<float>(200.0 + (seen < left.cols ? strip(seen, y) : 0.0)) + noise(random);
        }
    const RectifiedCapture capture{prepareForTracking(left), prepareForTracking(right),
                                   cv::Mat(region.size(), CV_32F, cv::Scalar(static_cast<float>(disparity)))};
    Parameters p;
    const cv::Mat measurable = measurableRing(capture, ring, p);
    EXPECT_EQ(cv::countNonZero(measurable & ~ring), 0);
    const cv::Rect stripInside(64, 40, 72, 6);  // off the strip's edges by the patch's reach
    EXPECT_GT(cv::countNonZero(measurable(stripInside)), 0.95 * stripInside.area());
    cv::Mat sky = ring.clone();
    sky(cv::Rect(60, 36, 80, 14)).setTo(0);
    EXPECT_EQ(cv::countNonZero(measurable & sky), 0);
    // Without the right eye's texture where the matcher put it, nothing is measured.
    const RectifiedCapture elsewhere{capture.left, capture.right, cv::Mat(region.size(), CV_32F, cv::Scalar(3.0f))};
    EXPECT_LT(cv::countNonZero(measurableRing(elsewhere, ring, p)), 0.05 * stripInside.area());
}

// A grid: the region's nodes in rows 10-19; above it a bead rising to 5 mm whose rim falls to
// 0.3 mm, a noise speck touching the region that never reaches the threshold, and a bird above
// the ring's middle, far from the region.
TEST(BeyondOutline, IceTouchesTheObjectRisesAboveTheNoiseAndIsTakenDownToItsFooting) {
    cv::Mat inside = cv::Mat::zeros(30, 60, CV_8U);
    inside.rowRange(10, 20).setTo(255);
    cv::Mat rise(30, 60, CV_64F, cv::Scalar(kNaN));
    for (int i = 5; i < 25; ++i) {
        rise.at<double>(9, i) = 5.0;
        rise.at<double>(8, i) = 2.5;
        rise.at<double>(7, i) = 0.3;  // the bead's rim: under the threshold, still the bead's
        rise.at<double>(6, i) = -0.4;
    }
    rise.at<double>(9, 40) = 1.2;  // noise at the outline
    rise.at<double>(9, 41) = 0.8;
    rise.at<double>(2, 50) = 9.0;  // a bird
    rise.at<double>(3, 50) = 9.0;
    const cv::Mat ice = iceBeyondOutline(rise, inside, 2.0);
    EXPECT_EQ(cv::countNonZero(ice), 60);
    EXPECT_TRUE(ice.at<std::uint8_t>(7, 10));
    EXPECT_FALSE(ice.at<std::uint8_t>(6, 10));
    EXPECT_FALSE(ice.at<std::uint8_t>(9, 40));
    EXPECT_FALSE(ice.at<std::uint8_t>(2, 50));
    EXPECT_EQ(cv::countNonZero(ice & inside), 0);
}

// Ice reaching the ring's outer edge (row 0, above a region from row 12 down, with a gap of two
// unmeasured rows next to it): an icicle standing at least twice the least that counts from the
// outline to the edge is counted where it meets the edge; one at 1.5 times is not, nor a spike of
// the rise's error out at the edge on noise that touches the outline (that part counts as ice,
// but not as ice that reaches the edge), nor a tapered part that does not touch the region.
TEST(BeyondOutline, IceAtTheRingsEdgeIsWhatStandsThereAllTheWayFromTheOutline) {
    constexpr double kMinRiseMm = 2.0;
    constexpr int kGapNodes = 2;
    cv::Mat inside = cv::Mat::zeros(20, 60, CV_8U);
    inside.rowRange(12, 20).setTo(255);
    cv::Mat ringEdge = cv::Mat::zeros(inside.size(), CV_8U);
    ringEdge.row(0).setTo(255);
    cv::Mat thickness(inside.size(), CV_64F, cv::Scalar(kNaN));
    cv::Mat beyond = cv::Mat::zeros(inside.size(), CV_8U);
    auto column = [&](int i, double rootMm, double edgeMm) {  // rows 0..9: the gap is rows 10, 11
        for (int j = 0; j <= 9; ++j) {
            thickness.at<double>(j, i) = edgeMm + (rootMm - edgeMm) * j / 9.0;
            beyond.at<std::uint8_t>(j, i) = 255;
        }
    };
    column(5, 12.0, 4.5);   // an icicle past the ring, twice the threshold and more all the way
    column(6, 12.0, 4.5);
    column(20, 12.0, 3.0);  // one whose tip crosses the edge at 1.5 times it
    for (int i = 30; i < 45; ++i) column(i, 1.0, 1.0);  // the rise's noise, touching the outline
    thickness.at<double>(0, 37) = 4.7;                  // and a spike of it at the edge
    const cv::Mat none;
    EXPECT_EQ(iceAtRingEdge(beyond, none, thickness, inside, ringEdge, kMinRiseMm, kGapNodes), 2);
    // Seen only by the background it hides: counted when it touches the region, whatever its height.
    cv::Mat tapered = cv::Mat::zeros(inside.size(), CV_8U);
    tapered(cv::Rect(50, 0, 2, 10)).setTo(255);  // from the edge to the gap
    tapered(cv::Rect(55, 0, 2, 5)).setTo(255);   // a cloud out at the edge alone
    EXPECT_EQ(iceAtRingEdge(beyond, tapered, thickness, inside, ringEdge, kMinRiseMm, kGapNodes), 4);
    // Without the gap, what stops two rows short of the region does not touch it.
    EXPECT_EQ(iceAtRingEdge(beyond, tapered, thickness, inside, ringEdge, kMinRiseMm, 0), 0);
}

// A bead seen only by the sky it hides: 8 nodes in front of the region's 10 rows, 3 of them next
// to the outline where the sky could not be compared, with 6 mm of ice on the outline. Its
// thickness falls from the outline's to nothing at its silhouette as a rounded bead's, 2/3 of
// height times width; a cloud behind the clean part of the edge is no ice, nor a bird off it.
TEST(BeyondOutline, IceSeenByTheBackgroundItHidesIsTaperedFromTheOutlinesHeight) {
    cv::Mat inside = cv::Mat::zeros(40, 60, CV_8U);
    inside.rowRange(20, 30).setTo(255);
    cv::Mat hidden = cv::Mat::zeros(40, 60, CV_8U);
    hidden(cv::Rect(10, 12, 20, 5)).setTo(255);  // rows 12-16: the bead beyond the 3-row gap
    hidden(cv::Rect(40, 16, 10, 4)).setTo(255);  // a cloud behind the clean edge
    hidden(cv::Rect(40, 2, 5, 3)).setTo(255);    // a bird
    cv::Mat edge(40, 60, CV_64F, cv::Scalar(0.2));
    edge.colRange(0, 35).setTo(6.0);
    cv::Mat thickness(40, 60, CV_64F, cv::Scalar(kNaN));
    const cv::Mat ice = taperedIce(hidden, inside, edge, 2.0, 3, thickness);
    EXPECT_EQ(cv::countNonZero(ice & inside), 0);
    EXPECT_EQ(cv::countNonZero(ice.colRange(35, 60)), 0);
    EXPECT_TRUE(ice.at<std::uint8_t>(19, 20));  // in the gap next to the outline
    EXPECT_TRUE(ice.at<std::uint8_t>(12, 20));
    EXPECT_FALSE(ice.at<std::uint8_t>(11, 20));
    // Highest next to the outline, falling towards the silhouette.
    EXPECT_NEAR(thickness.at<double>(19, 20), 6.0, 0.2);
    EXPECT_GT(thickness.at<double>(16, 20), thickness.at<double>(13, 20));
    EXPECT_LT(thickness.at<double>(12, 20), 1.5);
    double column = 0;
    for (int j = 0; j < 20; ++j)
        if (ice.at<std::uint8_t>(j, 20)) column += thickness.at<double>(j, 20);
    EXPECT_NEAR(column, 2.0 / 3.0 * 6.0 * 8.0, 3.0);
    // What stands where the outline reads too thin (the cloud) is not ice, but the least that
    // would have counted is kept for the budget; not for the bead, nor for the bird off the edge.
    cv::Mat thin(40, 60, CV_64F, cv::Scalar(kNaN));
    EXPECT_EQ(cv::countNonZero(taperedIce(hidden, inside, edge, 2.0, 3, thickness, &thin) != ice), 0);
    EXPECT_NEAR(thin.at<double>(19, 45), 2.0, 0.3);
    EXPECT_LT(thin.at<double>(16, 45), thin.at<double>(19, 45));
    EXPECT_TRUE(std::isnan(thin.at<double>(15, 20)));
    EXPECT_TRUE(std::isnan(thin.at<double>(3, 42)));
}

// A slanted outline is a staircase on the grid: closing the gap between the region and what hides
// the background must not fill the staircase's own notches, where nothing hid anything.
TEST(BeyondOutline, TheNotchesOfASlantedOutlineAreNotIce) {
    cv::Mat inside = cv::Mat::zeros(60, 120, CV_8U);
    for (int i = 0; i < 120; ++i) {
        // Steps of 6 nodes, 2 nodes high, with a tooth in each: the region sampled off a raster.
        const int top = 20 + 2 * (i / 6) / 4 + ((i % 6) == 2 ? -2 : 0);
        inside(cv::Range(top, 50), cv::Range(i, i + 1)).setTo(255);
    }
    const cv::Mat edge(60, 120, CV_64F, cv::Scalar(10.0));
    cv::Mat thickness(60, 120, CV_64F, cv::Scalar(kNaN));
    const cv::Mat nothing = cv::Mat::zeros(60, 120, CV_8U);
    EXPECT_EQ(cv::countNonZero(taperedIce(nothing, inside, edge, 2.0, 5, thickness)), 0);
    // A bead hiding the background beyond the gap still stands, and the nodes between it and the
    // region with it.
    cv::Mat hidden = cv::Mat::zeros(60, 120, CV_8U);
    hidden(cv::Rect(40, 8, 30, 5)).setTo(255);
    const cv::Mat ice = taperedIce(hidden, inside, edge, 2.0, 5, thickness);
    EXPECT_TRUE(ice.at<std::uint8_t>(10, 55));
    EXPECT_TRUE(ice.at<std::uint8_t>(18, 55));
    EXPECT_EQ(cv::countNonZero(ice.colRange(0, 30)), 0);
    EXPECT_EQ(cv::countNonZero(ice.colRange(80, 120)), 0);
}

// A strip 5 nodes wide is 5 wide across all of it, edges too; a cone hanging from it is as wide
// as its section at each height, its root wider than its tip; a lone node is one node wide.
TEST(BeyondOutline, WidthAcrossIsTheLargestDiscThatCoversTheNode) {
    cv::Mat parts = cv::Mat::zeros(80, 80, CV_8U);
    cv::rectangle(parts, cv::Rect(10, 10, 60, 5), cv::Scalar(255), cv::FILLED);  // rows 10-14
    cv::fillConvexPoly(parts, std::vector<cv::Point>{{30, 15}, {50, 15}, {40, 75}}, cv::Scalar(255));
    parts.at<std::uint8_t>(78, 5) = 255;
    const cv::Mat width = widthAcrossMm(parts, 2.0);
    ASSERT_EQ(width.type(), CV_64FC1);
    EXPECT_NEAR(width.at<double>(12, 15), 10.0, 1e-6);  // 5 nodes of 2 mm
    EXPECT_NEAR(width.at<double>(10, 15), 10.0, 1e-6);  // its edge lies in the same disc
    EXPECT_NEAR(width.at<double>(78, 5), 2.0, 1e-6);
    EXPECT_EQ(width.at<double>(5, 5), 0.0);
    // The cone is 20 nodes wide at its root and 0 at its tip: 2 mm nodes, a disc fits about 14 of
    // them near the root (the triangle's incircle there), a few near the tip.
    const double root = width.at<double>(22, 40), tip = width.at<double>(70, 40);
    EXPECT_GT(root, 20.0);
    EXPECT_LT(root, 40.0);
    EXPECT_LE(tip, 6.0);  // 5 nodes above the tip the section is 2 or 3 nodes
    EXPECT_GT(root, 4 * tip);
    EXPECT_TRUE(cv::countNonZero((width > 0) != (parts > 0)) == 0);
    // A part that fills the grid ends at its edge: 7 x 5 nodes of 1 mm are 5 wide in the middle.
    const cv::Mat all = widthAcrossMm(cv::Mat(5, 7, CV_8U, cv::Scalar(255)), 1.0);
    EXPECT_NEAR(all.at<double>(2, 3), 5.0, 1e-6);
    EXPECT_NEAR(all.at<double>(0, 3), 5.0, 1e-6);  // the disc in the middle reaches its edge
    EXPECT_LT(all.at<double>(0, 0), 5.0);           // but not its corners
}

}  // namespace
}  // namespace icewatch::volume
