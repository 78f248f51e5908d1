// The estimate's gates, each on what the stage before it would give it: every one refuses what it
// judges with a reason that names it, and lets through what it does not.
#include "core/volume/gates.hpp"

#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "tests/core/volume/test_planes.hpp"

namespace icewatch::volume {
namespace {

// A plane `deg` out of the view 1 m ahead, its normal towards the camera.
PlaneFrame planeTurnedBy(double deg) {
    const double a = deg * CV_PI / 180.0;
    PlaneFrame plane;
    plane.origin = {0, 0, 1000};
    plane.normal = {0, -std::sin(a), -std::cos(a)};
    plane.axisU = {1, 0, 0};
    plane.axisV = plane.normal.cross(plane.axisU);
    return plane;
}

ThicknessMap mapOf(int insideNodes, int beyondAtRingEdgeNodes = 0, int taperedNodes = 0) {
    ThicknessMap map;
    map.insideNodes = insideNodes;
    map.beyondAtRingEdgeNodes = beyondAtRingEdgeNodes;
    map.taperedNodes = taperedNodes;
    return map;
}

TEST(Gates, ARegionFoundByDepthThatReachesMostOfTheFrameEdgeIsTheView) {
    Surface baseline;
    baseline.roi = cv::Mat(480, 640, CV_8U, cv::Scalar(255));
    baseline.roiSegmented = true;
    const auto view = baselineRegionProblem(baseline);
    ASSERT_TRUE(view.has_value());
    EXPECT_NE(view->find("frame's edge"), std::string::npos) << *view;
    EXPECT_NE(view->find("draw the object's outline"), std::string::npos) << *view;
    // Drawn by hand, the same region is the object as drawn.
    baseline.roiSegmented = false;
    EXPECT_FALSE(baselineRegionProblem(baseline).has_value());
    // Found by depth in the middle of the view, it is an object.
    baseline.roi.setTo(0);
    baseline.roi(cv::Rect(200, 150, 240, 180)).setTo(255);
    baseline.roiSegmented = true;
    EXPECT_FALSE(baselineRegionProblem(baseline).has_value());
    baseline.roi.setTo(0);
    const auto none = baselineRegionProblem(baseline);
    ASSERT_TRUE(none.has_value());
    EXPECT_NE(none->find("no region"), std::string::npos) << *none;
}

TEST(Gates, APlaneSeenEdgeOnIsNotTheObjectsSurface) {
    // The ground 100 mm below the camera, seen 1 m ahead: 84° out of the view.
    const auto ground = edgeOnProblem(test::groundBelowCamera());
    ASSERT_TRUE(ground.has_value());
    EXPECT_NE(ground->find("edge-on"), std::string::npos) << *ground;
    EXPECT_FALSE(edgeOnProblem(planeTurnedBy(0)).has_value());
    EXPECT_FALSE(edgeOnProblem(planeTurnedBy(60)).has_value()) << "a blade on a table seen from 30° above";
}

TEST(Gates, FaintTextureRefusesOnlyWhereNoBackgroundFixesTheMotion) {
    const Parameters p;
    Surface baseline, current;
    baseline.quality.contrast = 0.5 * p.minContrastObjectMotion;
    current.quality.contrast = 2.0 * p.minContrastObjectMotion;
    MotionEstimate motion;
    motion.backgroundEvidence = 0;
    const auto faint = faintTextureProblem(baseline, current, motion, p);
    ASSERT_TRUE(faint.has_value());
    EXPECT_NE(faint->find("baseline image's texture is too faint"), std::string::npos) << *faint;
    motion.backgroundEvidence = 500;
    EXPECT_FALSE(faintTextureProblem(baseline, current, motion, p).has_value());
    motion.backgroundEvidence = 0;
    baseline.quality.contrast = current.quality.contrast;
    EXPECT_FALSE(faintTextureProblem(baseline, current, motion, p).has_value());
}

TEST(Gates, AThicknessMapOverNothingOrReachingTheRingsEdgeIsRefused) {
    const Parameters p;
    const auto nothing = thicknessMapProblem(mapOf(0), p);
    ASSERT_TRUE(nothing.has_value());
    EXPECT_NE(nothing->find("covers no part"), std::string::npos) << *nothing;
    const auto reaching = thicknessMapProblem(mapOf(1000, 7), p);
    ASSERT_TRUE(reaching.has_value());
    EXPECT_NE(reaching->find("7 nodes at its edge"), std::string::npos) << *reaching;
    EXPECT_FALSE(thicknessMapProblem(mapOf(1000), p).has_value());
}

TEST(Gates, AGridFilledBeyondItsLimitIsRefusedAndAtItIsNot) {
    const Parameters p;
    EXPECT_FALSE(filledProblem(p.maxFilledPercent, p).has_value());
    const auto over = filledProblem(p.maxFilledPercent + 0.5, p);
    ASSERT_TRUE(over.has_value());
    EXPECT_NE(over->find("has no measurement"), std::string::npos) << *over;
}

TEST(Gates, AMatchersSurfaceNoTextureChecksIsRefused) {
    Parameters p;
    const auto unchecked = uncheckedPushProblem(p.minEvidenceSamples - 1, p);
    ASSERT_TRUE(unchecked.has_value());
    EXPECT_NE(unchecked->find("cannot be checked: " + std::to_string(p.minEvidenceSamples - 1)), std::string::npos)
        << *unchecked;
    EXPECT_FALSE(uncheckedPushProblem(p.minEvidenceSamples, p).has_value());
}

TEST(Gates, IceBeyondTheOutlineOfAnObjectTurnedOutOfTheViewIsRefused) {
    const Parameters p;
    const PlaneFrame turned = planeTurnedBy(p.outlineMaxObliquityDeg + 10);
    VolumeResult result;
    // Seen only by the background it hides: read as if seen from the front.
    const auto tapered = outlineObliquityProblem(mapOf(1000, 0, 20), turned, result, p);
    ASSERT_TRUE(tapered.has_value());
    EXPECT_NE(tapered->find("seen from the front"), std::string::npos) << *tapered;
    EXPECT_FALSE(outlineObliquityProblem(mapOf(1000, 0, 20), planeTurnedBy(0), result, p).has_value());
    // Measured beyond the outline: refused when more than the outline's own uncertainty.
    result.budget.outlineMm3 = 1000;
    result.beyondOutlineMm3 = p.coverageFactor * 1000 + 1;
    const auto measured = outlineObliquityProblem(mapOf(1000), turned, result, p);
    ASSERT_TRUE(measured.has_value());
    EXPECT_NE(measured->find("hides what lies behind it"), std::string::npos) << *measured;
    result.beyondOutlineMm3 = p.coverageFactor * 1000 - 1;
    EXPECT_FALSE(outlineObliquityProblem(mapOf(1000), turned, result, p).has_value()) << "the outline's noise";
}

}  // namespace
}  // namespace icewatch::volume
