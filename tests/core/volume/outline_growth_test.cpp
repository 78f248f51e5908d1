// The outline against the sky: where it departs from the sky, and how far it grew beyond the
// object's motion on each long side.
#include "core/volume/outline_growth.hpp"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

namespace icewatch::volume {
namespace {

constexpr double kFocalPx = 800.0, kDepthMm = 850.0;

// An edge from the object's grey (inside) to the sky's over one pixel, at `edgePx` along a profile
// sampled every half pixel; the sky has a gradient, as soft clouds give it.
std::vector<float> edgeProfile(double edgePx, float object, float sky, float skySlopePerPx) {
    std::vector<float> p(57);
    for (std::size_t i = 0; i < p.size(); ++i) {
        const double s = 0.5 * static_cast<double>(i);
        const double w = std::clamp(s - edgePx + 0.5, 0.0, 1.0);  // share of the pixel that is sky
        p[i] = static_cast<float>(object + (sky - object) * w + skySlopePerPx * s);
    }
    return p;
}

TEST(OutlineGrowth, TheSkyEdgeMovesWithTheEdgeAndNotWithTheSkysGradient) {
    const double a = skyEdgeInProfile(edgeProfile(10.0, 150, 210, 0.0f), 0.5, 16, 3.0);
    ASSERT_GT(a, 0);
    for (const double shift : {0.3, 1.0, 2.7}) {
        const double b = skyEdgeInProfile(edgeProfile(10.0 + shift, 150, 210, 0.0f), 0.5, 16, 3.0);
        EXPECT_NEAR(b - a, shift, 0.05) << shift;
    }
    // A sky brightening outwards by 0.15 grey levels a pixel (a cloud's flank) moves it by little.
    EXPECT_NEAR(skyEdgeInProfile(edgeProfile(10.0, 150, 210, 0.15f), 0.5, 16, 3.0), a, 0.05);
    // A darker or brighter object against the same sky: the same edge within a tenth of a pixel.
    EXPECT_NEAR(skyEdgeInProfile(edgeProfile(10.0, 100, 210, 0.0f), 0.5, 16, 3.0), a, 0.1);
    EXPECT_NEAR(skyEdgeInProfile(edgeProfile(10.0, 240, 210, 0.0f), 0.5, 16, 3.0), a, 0.1);
}

TEST(OutlineGrowth, NoSkyOrNoEdgeIsNoEdge) {
    std::vector<float> textured(57);
    for (std::size_t i = 0; i < textured.size(); ++i) textured[i] = 180.0f + 8.0f * std::sin(1.3f * static_cast<float>(i));
    EXPECT_LT(skyEdgeInProfile(textured, 0.5, 16, 3.0), 0) << "a table, not a sky";
    EXPECT_LT(skyEdgeInProfile(std::vector<float>(57, 200.0f), 0.5, 16, 3.0), 0) << "sky all along";
}

// A dark blade-like band across a sky, seen facing the camera at 850 mm.
struct Scene {
    cv::Mat baseline, current, roi, featureless;
    PlaneFrame plane;
    cv::Matx33d k{kFocalPx, 0, 200, 0, kFocalPx, 120, 0, 0, 1};
};

// The band is rows [top, bottom) and columns [60, 340); `lipTop`, `lipBottom`: px of ice standing
// out of it in the current capture, brighter than the sky; `shift`: how far the band moved in it.
Scene bandScene(double lipTopPx, double lipBottomPx, cv::Point2d shift) {
    Scene s;
    const int w = 400, h = 240;
    const double top = 100, bottom = 140;
    std::mt19937 random(5);
    std::normal_distribution<float> noise(0.0f, 0.4f);
    auto render = [&](double dx, double dy, double lipTop, double lipBottom, bool after) {
        cv::Mat image(h, w, CV_32F);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const double sky = 200.0 + 0.05 * y;
                // Coverage of the pixel by the band and by its lips, rows only (the ends are far).
                auto cover = [&](double a, double b) { return std::clamp(std::min(b, y + 1.0) - std::max(a, double(y)), 0.0, 1.0); };
                const bool inColumns = x - dx >= 60 && x - dx < 340;
                const double band = inColumns ? cover(top + dy, bottom + dy) : 0.0;
                const double lips = inColumns && after ? cover(top + dy - lipTop, top + dy) + cover(bottom + dy, bottom + dy + lipBottom) : 0.0;
                const double texture = 6.0 * std::sin(0.35 * x) * std::sin(0.3 * y);
                image.at<float>(y, x) = static_cast<float>(sky * (1 - band - lips) + (140.0 + texture) * band +
                                                           1.12 * sky * lips) + noise(random);
            }
        return image;
    };
    s.baseline = render(0, 0, 0, 0, false);
    s.current = render(shift.x, shift.y, lipTopPx, lipBottomPx, true);
    s.roi = cv::Mat::zeros(h, w, CV_8U);
    s.roi(cv::Rect(60, 100, 280, 40)).setTo(255);
    s.featureless = cv::Mat(h, w, CV_8U, cv::Scalar(255));
    s.featureless(cv::Rect(58, 98, 284, 44)).setTo(0);
    s.plane.origin = {0, 0, kDepthMm};
    s.plane.axisU = {1, 0, 0};
    s.plane.axisV = {0, 1, 0};
    s.plane.normal = {0, 0, -1};
    return s;
}

OutlineGrowth growthOf(const Scene& s, const RigidTransform& toBaseline) {
    return outlineGrowth(s.baseline, s.current, s.roi, s.featureless, s.plane, toBaseline, s.k,
                         cv::Rect(0, 0, s.roi.cols, s.roi.rows));
}

TEST(OutlineGrowth, ALayerOverBothEdgesGrowsBothLongSides) {
    const Scene s = bandScene(3.0, 1.5, {0, 0});
    const OutlineGrowth g = growthOf(s, RigidTransform{});
    ASSERT_GE(g.stations[0], 20);
    ASSERT_GE(g.stations[1], 20);
    const double mmPerPx = kDepthMm / kFocalPx;
    EXPECT_NEAR(std::max(g.medianMm[0], g.medianMm[1]), 3.0 * mmPerPx, 0.1);
    EXPECT_NEAR(std::min(g.medianMm[0], g.medianMm[1]), 1.5 * mmPerPx, 0.1);
    EXPECT_TRUE(g.bothSidesGrew);
}

TEST(OutlineGrowth, IceOnOneEdgeIsNotALayerOverBoth) {
    const OutlineGrowth g = growthOf(bandScene(4.0, 0.0, {0, 0}), RigidTransform{});
    EXPECT_NEAR(std::min(std::abs(g.medianMm[0]), std::abs(g.medianMm[1])), 0.0, 0.05);
    EXPECT_FALSE(g.bothSidesGrew);
}

// The band moved 2.5 px down and 3 px along: with the motion that says so, nothing grew; with none
// (a motion the registration got wrong), one side grew and the other shrank, and that is no layer.
TEST(OutlineGrowth, AMovedObjectWithItsMotionDidNotGrow) {
    const Scene s = bandScene(0.0, 0.0, {3.0, 2.5});
    RigidTransform toBaseline;  // current -> baseline: back by the shift on the plane
    toBaseline.translation = {-3.0 * kDepthMm / kFocalPx, -2.5 * kDepthMm / kFocalPx, 0.0};
    const OutlineGrowth moved = growthOf(s, toBaseline);
    ASSERT_GE(moved.stations[0], 20);
    ASSERT_GE(moved.stations[1], 20);
    EXPECT_NEAR(moved.medianMm[0], 0.0, 0.05);
    EXPECT_NEAR(moved.medianMm[1], 0.0, 0.05);
    EXPECT_FALSE(moved.bothSidesGrew);
    const OutlineGrowth unregistered = growthOf(s, RigidTransform{});
    EXPECT_NEAR(unregistered.medianMm[0] + unregistered.medianMm[1], 0.0, 0.1);
    EXPECT_FALSE(unregistered.bothSidesGrew);
}

TEST(OutlineGrowth, AgainstATableNothingIsMeasured) {
    Scene s = bandScene(3.0, 3.0, {0, 0});
    s.featureless.setTo(0);
    const OutlineGrowth g = growthOf(s, RigidTransform{});
    EXPECT_EQ(g.stations[0] + g.stations[1], 0);
    EXPECT_FALSE(g.bothSidesGrew);
}

}  // namespace
}  // namespace icewatch::volume
