#include "core/volume/uncertainty.hpp"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "core/volume/beyond_outline.hpp"

namespace icewatch::volume {
namespace {

// A flat 20 x 10 grid of 2 mm cells, all of it possible ice, 1 mm thick everywhere.
ThicknessMap flatMap() {
    ThicknessMap map;
    map.grid = GridSpec{0, 0, 2, 2, 20, 10};
    map.thickness = cv::Mat(10, 20, CV_64F, cv::Scalar(1.0));
    map.baselineHeight = cv::Mat(10, 20, CV_64F, cv::Scalar(0.0));
    map.inside = cv::Mat(10, 20, CV_8U, cv::Scalar(1));
    map.onIce = cv::Mat(10, 20, CV_8U, cv::Scalar(1));
    map.insideNodes = map.iceNodes = 200;
    return map;
}

// Bare on the left half, heightMm of ice on the right: one straight step across the grid.
ThicknessMap stepMap(double heightMm) {
    ThicknessMap map = flatMap();
    map.thickness.colRange(0, 10).setTo(0.0);
    map.thickness.colRange(10, 20).setTo(heightMm);
    return map;
}

PlaneFrame planeOneMetreAway() {
    PlaneFrame plane;
    plane.origin = {0, 0, 1000};
    return plane;
}

// The outline tests' view: the plane 1 m away, 1 mm a pixel, an edge margin of 3 px and a footing
// known to 1.5 mm.
struct OutlineView {
    PlaneFrame plane;
    ViewGeometry view{1000.0, 60.0, 1000.0};
    Parameters p;
    OutlineView() {
        plane.origin = {0, 0, 1000};
        p.edgeMarginPx = 3;
        p.outlineFootingMm = 1.5;
    }
};

TEST(VolumeUncertainty, ThePushCountsWithWhatIsNotKnownOfIt) {
    const ThicknessMap map = flatMap();
    PlaneFrame plane;
    plane.origin = {0, 0, 1000};
    const ViewGeometry view{1000.0, 60.0, 1000.0};  // ΔZ of 1 px: 1000² / (1000 · 60) mm
    const double depthPerPx = 1000.0 * 1000.0 / (1000.0 * 60.0);
    const double area = 200 * 4.0;
    MatcherPush push;
    push.meanPx = 0.01;
    push.sigmaPx = 0.0;
    const Parameters p;
    EXPECT_NEAR(volumeUncertainty(map, plane, {}, push, view, p, 800.0).pushMm3, 0.01 * depthPerPx * area, 1e-9);
    // Measured to ±0.05 px: a push of 0.01 px is known no better than that.
    push.sigmaPx = 0.05;
    EXPECT_NEAR(volumeUncertainty(map, plane, {}, push, view, p, 800.0).pushMm3,
                std::hypot(0.01, 0.05) * depthPerPx * area, 1e-9);
}

// A step 6 mm high across the grid (the rows the gradient is taken on: 8 of 2 mm), seen 1 m
// away at 1 mm a pixel: an edge reaching out by 6 px, all of it as its σ (the error is all on one
// side, and beside a step the matcher's wider reach may stand), is 6 mm of its 6 mm height along
// 16 mm. Facing the camera the windows' own reach is nothing, but a step as low as this one
// (0.36 px) their weights do not see, and it reaches out by facingFatteningPx.
TEST(VolumeUncertainty, AnEdgeSeenAtAnAngleMayReachOutAsFarAsTheWindows) {
    const ThicknessMap map = stepMap(6.0);
    const PlaneFrame plane = planeOneMetreAway();
    const Parameters p;
    ViewGeometry view{1000.0, 60.0, 1000.0};
    EXPECT_NEAR(volumeUncertainty(map, plane, {}, {}, view, p, 800.0).fatteningMm3, p.facingFatteningPx * 6.0 * 16.0,
                0.05 * p.facingFatteningPx * 6.0 * 16.0);
    view.fatteningPx = 6.0;
    const UncertaintyBudget b = volumeUncertainty(map, plane, {}, {}, view, p, 800.0);
    EXPECT_NEAR(b.fatteningMm3, 6.0 * 6.0 * 16.0, 0.05 * 6.0 * 6.0 * 16.0);
    // The same edges as the edge term's, at another width.
    EXPECT_NEAR(b.fatteningMm3, b.edgeMm3 * 6.0 / p.edgeUncertaintyPx, 1e-9);
    UncertaintyBudget without = b;
    without.fatteningMm3 = 0;
    EXPECT_GT(expandedUncertainty(b, 2.0), expandedUncertainty(without, 2.0));
}

// Facing the camera a step tall enough for the windows' weights to see (60 mm: 3.6 px here) counts
// only up to the separable step (1.5 px: 25 mm); the edge term still counts all of it.
TEST(VolumeUncertainty, AFacingStepCountsItsFatteningOnlyUpToTheSeparableHeight) {
    const ThicknessMap map = stepMap(60.0);
    const PlaneFrame plane = planeOneMetreAway();
    Parameters p;
    const ViewGeometry view{1000.0, 60.0, 1000.0};
    const double separableMm = p.fatteningSeparableStepPx * 1000.0 * 1000.0 / (1000.0 * 60.0);
    const UncertaintyBudget b = volumeUncertainty(map, plane, {}, {}, view, p, 800.0);
    EXPECT_NEAR(b.fatteningMm3, p.facingFatteningPx * separableMm * 16.0, 0.05 * p.facingFatteningPx * separableMm * 16.0);
    EXPECT_NEAR(b.edgeMm3, p.edgeUncertaintyPx * 60.0 * 16.0, 0.05 * p.edgeUncertaintyPx * 60.0 * 16.0);
    p.facingFatteningPx = 0.0;
    EXPECT_EQ(volumeUncertainty(map, plane, {}, {}, view, p, 800.0).fatteningMm3, 0.0);
}

// A band the camera did not see along its line of sight (behind a block's far edge seen at an
// angle), bridged 6 mm above its least over 10 nodes: from the far surface to the near one, the
// bridge the middle, uniformly. Where nothing was hidden the term is nothing.
TEST(VolumeUncertainty, ABandHiddenAlongTheLineOfSightCountsFromTheFarSurfaceToTheNearOne) {
    ThicknessMap map = flatMap();
    PlaneFrame plane;
    plane.origin = {0, 0, 1000};
    const ViewGeometry view{1000.0, 60.0, 1000.0};
    const Parameters p;
    map.hiddenMm = cv::Mat(10, 20, CV_64F, cv::Scalar(0.0));
    EXPECT_EQ(volumeUncertainty(map, plane, {}, {}, view, p, 800.0).hiddenMm3, 0.0);
    map.hiddenMm(cv::Rect(5, 2, 10, 1)).setTo(6.0);
    EXPECT_NEAR(volumeUncertainty(map, plane, {}, {}, view, p, 800.0).hiddenMm3, 10 * 6.0 * 4.0 / std::sqrt(3.0), 1e-9);
}

// Next to the outline the ring is blind for edge_margin_px and a ring patch's reach: ice on the
// outline may stand out of it that far unseen. Ice beyond the outline closes that edge; its
// footing counts instead.
TEST(VolumeUncertainty, IceOnTheOutlineMayStandOutOfItWhereTheRingIsBlind) {
    ThicknessMap map = flatMap();
    map.beyond = cv::Mat::zeros(10, 20, CV_8U);
    const OutlineView o;
    const PlaneFrame& plane = o.plane;
    const ViewGeometry& view = o.view;
    const Parameters& p = o.p;
    const double blindMm = 3.0 + kRingPatchRadiusPx;
    // The whole border of the 40 x 20 mm grid, 1 mm thick: 120 mm of outline.
    EXPECT_NEAR(volumeUncertainty(map, plane, {}, {}, view, p, 800.0).outlineMm3, blindMm * 120.0 / std::sqrt(3.0), 1e-9);
    // The top row's nodes out of the region and ice beyond it: the top edge is closed, the sides
    // shorter by a node, and the footing of the ice beyond counts.
    map.inside.row(0).setTo(0);
    map.beyond.row(0).setTo(255);
    map.beyondNodes = 20;
    const double unseen = blindMm * (120.0 - 40.0 - 4.0) / std::sqrt(3.0);
    EXPECT_NEAR(volumeUncertainty(map, plane, {}, {}, view, p, 800.0).outlineMm3,
                std::hypot(unseen, 1.5 * 20 * 4.0), 1e-9);
    map.thickness.setTo(0.0);
    EXPECT_NEAR(volumeUncertainty(map, plane, {}, {}, view, p, 800.0).outlineMm3, 1.5 * 20 * 4.0, 1e-9);
}

// Ice seen standing out of the outline only by the sky it hides is tapered from the height read on
// the outline, and beside it the matcher read the outline against the ice now and against the sky
// before: the ice tapered and the ice read within outline_fringe_px of it may be as much again.
TEST(VolumeUncertainty, IceBesideWhatStandsOutAgainstTheSkyMayBeAsMuchAgain) {
    ThicknessMap map = flatMap();
    const OutlineView o;
    const PlaneFrame& plane = o.plane;
    const ViewGeometry& view = o.view;
    const Parameters& p = o.p;
    // The top row beyond the outline, tapered, 1 mm thick.
    map.inside.row(0).setTo(0);
    map.beyond = cv::Mat::zeros(10, 20, CV_8U);
    map.beyond.row(0).setTo(255);
    map.tapered = map.beyond.clone();
    map.beyondNodes = map.taperedNodes = 20;
    const double blindMm = 3.0 + kRingPatchRadiusPx;
    const double footing = 1.5 * 20 * 4.0;
    const double unseen = blindMm * (120.0 - 40.0 - 4.0) / std::sqrt(3.0);
    const double tapered = 20 * 4.0;
    // Between a wedge (3/4 of the taper) and, since a row one node (2 mm) wide may be as deep as it
    // is wide, 2 mm on every node: more than a block of the outline's 1 mm (1.5 times the taper).
    const double shape = (20 * 2.0 * 4.0 - 0.75 * tapered) / std::sqrt(12.0);
    auto outline = [&](double pull) { return std::sqrt(footing * footing + unseen * unseen + shape * shape + pull * pull); };
    EXPECT_NEAR(volumeUncertainty(map, plane, {}, {}, view, p, 800.0).outlineMm3, outline(tapered / std::sqrt(3.0)), 1e-9);
    map.fringe = cv::Mat::zeros(10, 20, CV_8U);
    // Off the sides, whose nodes are on the outline (what may stand out of it unseen stays as it was).
    const cv::Rect pulled(1, 1, 18, 3);
    map.fringe(pulled).setTo(255);
    map.thickness(pulled).setTo(2.0);
    const double fringe = 54 * 2.0 * 4.0;
    EXPECT_NEAR(volumeUncertainty(map, plane, {}, {}, view, p, 800.0).outlineMm3,
                outline((tapered + fringe) / std::sqrt(3.0)), 1e-6);
    // What hid the background where the outline read too thin for ice: the least that would have
    // counted, 1.5 mm on two nodes, may be there too.
    map.thinBeyondMm = cv::Mat(10, 20, CV_64F, cv::Scalar(std::numeric_limits<double>::quiet_NaN()));
    map.thinBeyondMm.at<double>(0, 3) = map.thinBeyondMm.at<double>(0, 4) = 1.5;
    EXPECT_NEAR(volumeUncertainty(map, plane, {}, {}, view, p, 800.0).outlineMm3,
                outline((tapered + fringe + 2 * 1.5 * 4.0) / std::sqrt(3.0)), 1e-6);
}

// An icicle hangs from a thin runback band: seen only by the sky it hides, it is tapered from the
// band's height, but it may be as deep as it is wide (a round section). A part 5 nodes (10 mm) wide
// and 6 long under a band read 0.5 mm thick: its shape may hold far more than a block of 0.5 mm.
TEST(VolumeUncertainty, IceSeenOnlyByTheSkyItHidesMayBeAsDeepAsItIsWide) {
    ThicknessMap map = flatMap();
    const OutlineView o;
    map.thickness.setTo(0.0);  // no ice on the outline: its blind band holds none
    map.inside.rowRange(4, 10).setTo(0);
    map.beyond = cv::Mat::zeros(10, 20, CV_8U);
    const cv::Rect icicle(8, 4, 5, 6);
    map.beyond(icicle).setTo(255);
    map.thickness(icicle).setTo(0.5);
    map.tapered = map.beyond.clone();
    map.beyondNodes = map.taperedNodes = 30;
    const double tapered = 30 * 0.5 * 4.0;
    const double widthMm3 = cv::sum(widthAcrossMm(map.tapered, 2.0))[0] * 4.0;
    EXPECT_GT(widthMm3, 30 * 6.0 * 4.0);  // most of it 10 mm wide, its corners less
    const double shape = (widthMm3 - 0.75 * tapered) / std::sqrt(12.0);
    const double footing = 1.5 * 30 * 4.0, pull = tapered / std::sqrt(3.0);
    const double outline = volumeUncertainty(map, o.plane, {}, {}, o.view, o.p, 100.0).outlineMm3;
    EXPECT_NEAR(outline, std::sqrt(footing * footing + shape * shape + pull * pull), 1e-9);
    // With the block's bound alone (a uniform over [0.75, 1.5] of the taper) the term would be
    // about half as wide.
    const double blockOnly = std::sqrt(footing * footing + std::pow(0.75 * tapered / std::sqrt(12.0), 2) + pull * pull);
    EXPECT_GT(outline, 1.8 * blockOnly);
}

}  // namespace
}  // namespace icewatch::volume
