#include "core/volume/match_region.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "core/common/error.hpp"

namespace icewatch::volume {
namespace {

// An ideal rig: f = 1000 px, B = 100 mm, same principal points: Z = f·B / d.
constexpr double kFocalPx = 1000, kBaselineMm = 100;
cv::Matx44d idealQ() {
    return cv::Matx44d(1, 0, 0, -320,  //
                       0, 1, 0, -240,  //
                       0, 0, 0, kFocalPx,  //
                       0, 0, 1.0 / kBaselineMm, 0);
}

// A region (a rectangle) at disparities from dNear down to dFar across it, background elsewhere.
struct Baseline {
    cv::Mat disparity, roi;
};
Baseline slantedRegion(cv::Rect region, float dFar, float dNear) {
    Baseline b;
    b.disparity = cv::Mat(480, 640, CV_32F, cv::Scalar(20.0f));
    b.roi = cv::Mat::zeros(480, 640, CV_8U);
    b.roi(region).setTo(255);
    for (int x = region.x; x < region.br().x; ++x) {
        const float d = dFar + (dNear - dFar) * float(x - region.x) / float(region.width - 1);
        b.disparity(cv::Rect(x, region.y, 1, region.height)).setTo(d);
    }
    return b;
}

TEST(MatchRegion, BandCoversTheRegionWidenedByIceAndMotionThroughTheDepth) {
    const Baseline b = slantedRegion({200, 150, 200, 100}, 100.0f, 110.0f);  // Z 1000 .. 909 mm
    Parameters p;
    p.maxIceThicknessMm = 50;
    p.maxRegistrationMm = 20;
    p.maxDisparity = 256;
    const MatchRegion m = matchRegionFromBaseline(b.disparity, b.roi, idealQ(), kFocalPx, p, 10);
    // Nearest: 909 - 50 - 20 mm -> 118.9 px; farthest: 1000 + 20 mm -> 98.0 px.
    const double nearD = kFocalPx * kBaselineMm / (kFocalPx * kBaselineMm / 109.9 - 70.0);
    const double farD = kFocalPx * kBaselineMm / (kFocalPx * kBaselineMm / 100.1 + 20.0);
    EXPECT_LE(m.band.min, farD - 1.0);
    EXPECT_GE(m.band.min, farD - 4.0);
    EXPECT_GE(m.band.max - 1, nearD + 1.0) << "the nearest disparity is not on the band's edge";
    EXPECT_LE(m.band.max, nearD + 5.0);
    // Margin: the matcher's reach, 20 mm at the nearest depth (22 px), and the wider of the
    // trackers' reach and the ring where ice beyond the outline is looked for (50 mm there).
    const double nearestMm = kFocalPx * kBaselineMm / 109.9;
    const int motionPx = static_cast<int>(std::ceil(20.0 * kFocalPx / nearestMm));
    const int ringPx = static_cast<int>(std::ceil(p.outlineGrowthMm * kFocalPx / nearestMm));
    ASSERT_GT(ringPx, p.trackRadiusPx + p.trackSearchPx);
    EXPECT_EQ(m.marginPx, 10 + motionPx + ringPx);
    p.outlineGrowthMm = 0;
    EXPECT_EQ(matchRegionFromBaseline(b.disparity, b.roi, idealQ(), kFocalPx, p, 10).marginPx,
              10 + motionPx + p.trackRadiusPx + p.trackSearchPx);
    EXPECT_EQ(m.regionBox, cv::Rect(200, 150, 200, 100));
    EXPECT_EQ(m.box, cv::Rect(200 - m.marginPx, 150 - m.marginPx, 200 + 2 * m.marginPx, 100 + 2 * m.marginPx));
}

TEST(MatchRegion, NoIceAllowanceNarrowsTheBandAndTheBoxStopsAtTheImage) {
    const Baseline b = slantedRegion({0, 0, 300, 480}, 60.0f, 60.0f);
    Parameters p;
    p.maxRegistrationMm = 1;
    p.maxIceThicknessMm = 0;
    const MatchRegion m = matchRegionFromBaseline(b.disparity, b.roi, idealQ(), kFocalPx, p, 10);
    EXPECT_LT(m.band.width(), 8);
    EXPECT_LT(m.band.min, 60);
    EXPECT_GT(m.band.max - 1, 60);
    EXPECT_EQ(m.box.x, 0);
    EXPECT_EQ(m.box.y, 0);
    EXPECT_EQ(m.box.height, 480);
    // The matcher's window reaches left by the band's largest disparity, clipped to the image.
    const cv::Rect w = matcherWindow(m, {640, 480});
    EXPECT_EQ(w, m.box);
}

TEST(MatchRegion, MatcherWindowReachesLeftByTheBand) {
    MatchRegion m;
    m.box = {300, 10, 100, 50};
    m.band = {40, 70};
    EXPECT_EQ(matcherWindow(m, {640, 480}), cv::Rect(230, 10, 170, 50));
}

TEST(MatchRegion, ARegionWithoutValidDisparityIsAnError) {
    Baseline b = slantedRegion({200, 150, 200, 100}, 100.0f, 110.0f);
    b.disparity.setTo(-1.0f);
    EXPECT_THROW(matchRegionFromBaseline(b.disparity, b.roi, idealQ(), kFocalPx, Parameters{}, 10), InvalidInput);
}

TEST(MatchRegion, AShiftThatTakesTheRegionWithinTheMatchersReachOfACutEdgeIsAProblem) {
    MatchRegion m;
    m.regionBox = {200, 150, 200, 100};
    m.reachPx = 10;
    m.marginPx = 40;
    m.box = {160, 110, 280, 180};
    m.band = {50, 80};
    const cv::Size image(640, 480);
    EXPECT_FALSE(regionProblem(m, image, {0, 0}));
    EXPECT_FALSE(regionProblem(m, image, {29.5, -30}));
    const auto problem = regionProblem(m, image, {31, 0});
    ASSERT_TRUE(problem);
    EXPECT_NE(problem->find("out of the region matched"), std::string::npos) << *problem;
    // An edge the image itself cuts costs the matcher nothing.
    m.box = {0, 110, 440, 180};
    EXPECT_FALSE(regionProblem(m, image, {-150, 0}));
    EXPECT_TRUE(regionProblem(m, image, {-201, 0}));
    // No region (the whole frame): never a problem.
    EXPECT_FALSE(regionProblem(MatchRegion{}, image, {500, 500}));
}

}  // namespace
}  // namespace icewatch::volume
