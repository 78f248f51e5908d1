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

// A profile across an edge from the object's grey (inside) to the sky's, sampled every half pixel
// (57 samples: 10 px in, 18 px out of an edge at 10 px), each sample a pixel's box seen through a
// Gaussian blur of `blurPx`; the sky has a gradient, as soft clouds give it. `rimPx` of something
// of grey `rim` may stand on the edge, outside it (a clear layer with the sky showing through).
std::vector<float> edgeProfile(double edgePx, float object, float sky, float skySlopePerPx, double blurPx = 0.0,
                               double rimPx = 0.0, float rim = 0.0f) {
    const double fine = 0.01;
    auto scene = [&](double u) {
        if (u < edgePx) return static_cast<double>(object);
        if (u < edgePx + rimPx) return static_cast<double>(rim);
        return sky + skySlopePerPx * u;
    };
    std::vector<float> p(57);
    for (std::size_t i = 0; i < p.size(); ++i) {
        const double s = 0.5 * static_cast<double>(i);
        double sum = 0, weight = 0;
        const double reach = 0.5 + 4.0 * blurPx;
        for (double u = s - reach; u <= s + reach; u += fine) {
            // A pixel's box (1 px) seen through the blur: the box's response to a Gaussian.
            const double w = blurPx > 0 ? 0.5 * (std::erf((u - s + 0.5) / (std::sqrt(2.0) * blurPx)) -
                                                 std::erf((u - s - 0.5) / (std::sqrt(2.0) * blurPx)))
                                        : (std::abs(u - s) <= 0.5 ? 1.0 : 0.0);
            sum += w * scene(u);
            weight += w;
        }
        p[i] = static_cast<float>(sum / weight);
    }
    return p;
}

double coveredOf(const std::vector<float>& profile) {
    const std::optional<double> w = coveredWidthPx(profile, 0.5, 10, 16, 3.0, 12.0);
    EXPECT_TRUE(w.has_value());
    return w.value_or(0.0);
}

TEST(OutlineGrowth, TheCoveredWidthMovesWithTheEdgeAndNotWithTheSkyItsContrastOrItsBlur) {
    const double a = coveredOf(edgeProfile(10.0, 150, 210, 0.0f));
    for (const double shift : {0.3, 1.0, 2.7}) {
        EXPECT_NEAR(coveredOf(edgeProfile(10.0 + shift, 150, 210, 0.0f)) - a, shift, 0.02) << shift;
    }
    // A sky brightening outwards by 0.15 grey levels a pixel (a cloud's flank) moves it by little.
    EXPECT_NEAR(coveredOf(edgeProfile(10.0, 150, 210, 0.15f)), a, 0.1);
    // A darker or brighter object against the same sky (a change of light on it alone).
    EXPECT_NEAR(coveredOf(edgeProfile(10.0, 100, 210, 0.0f)), a, 0.02);
    EXPECT_NEAR(coveredOf(edgeProfile(10.0, 240, 210, 0.0f)), a, 0.02);
    // Blur spreads the edge and keeps what it covers.
    for (const double blur : {0.7, 1.0, 2.0}) EXPECT_NEAR(coveredOf(edgeProfile(10.0, 150, 210, 0.0f, blur)), a, 0.03) << blur;
}

// A clear rim over the edge, the sky showing through it 12 % brighter, beside a darker object:
// what it covers is its width times its share of the object's contrast, negative as it stands on
// the other side of the sky's grey, sharp or blurred (where a threshold placing the edge read it
// as grown when sharp and shrunk when blurred, its bright rim and the dark edge cancelling).
TEST(OutlineGrowth, AClearRimOverTheEdgeCoversItsShareOfTheContrastSharpOrBlurred) {
    const double expected = -2.0 * (1.12 * 210 - 210) / (210 - 150);
    for (const double blur : {0.0, 1.0, 1.8, 2.0}) {
        const double clean = coveredOf(edgeProfile(10.0, 150, 210, 0.0f, blur));
        const double rimmed = coveredOf(edgeProfile(10.0, 150, 210, 0.0f, blur, 2.0, 1.12f * 210));
        EXPECT_NEAR(rimmed - clean, expected, 0.03) << blur;
    }
}

TEST(OutlineGrowth, NoSkyOrNoEdgeIsNoEdge) {
    std::vector<float> textured(57);
    for (std::size_t i = 0; i < textured.size(); ++i) textured[i] = 180.0f + 8.0f * std::sin(1.3f * static_cast<float>(i));
    EXPECT_FALSE(coveredWidthPx(textured, 0.5, 10, 16, 3.0, 12.0)) << "a table, not a sky";
    EXPECT_FALSE(coveredWidthPx(std::vector<float>(57, 200.0f), 0.5, 10, 16, 3.0, 12.0)) << "sky all along";
    EXPECT_FALSE(coveredWidthPx(edgeProfile(10.0, 205, 210, 0.0f), 0.5, 10, 16, 3.0, 12.0)) << "an object as grey as the sky";
}

// A dark blade-like band across a sky, seen facing the camera at 850 mm.
struct Scene {
    cv::Mat baseline, current, roi, featureless;
    PlaneFrame plane;
    cv::Matx33d k{kFocalPx, 0, 200, 0, kFocalPx, 120, 0, 0, 1};
};

// The band is rows [top, bottom) and columns [60, 340); `lipTop`, `lipBottom`: px of ice standing
// out of it in the current capture, brighter than the sky; `shift`: how far the band moved in it.
Scene bandScene(double lipTopPx, double lipBottomPx, cv::Point2d shift, double blurPx = 0.0) {
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
                const double texture = 6.0 * std::sin(0.35 * (x - dx)) * std::sin(0.3 * (y - dy));  // moves with it
                image.at<float>(y, x) = static_cast<float>(sky * (1 - band - lips) + (140.0 + texture) * band +
                                                           1.12 * sky * lips) + noise(random);
            }
        return image;
    };
    s.baseline = render(0, 0, 0, 0, false);
    s.current = render(shift.x, shift.y, lipTopPx, lipBottomPx, true);
    if (blurPx > 0) {
        cv::GaussianBlur(s.baseline, s.baseline, {0, 0}, blurPx, blurPx, cv::BORDER_REFLECT);
        cv::GaussianBlur(s.current, s.current, {0, 0}, blurPx, blurPx, cv::BORDER_REFLECT);
    }
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

// Clear lips 12 % brighter than the sky over both edges of a band 60 grey levels darker than it:
// each side covers its lip's width times -0.4, sharp or blurred by 2 px.
TEST(OutlineGrowth, AClearLayerOverBothEdgesChangesBothLongSides) {
    const double mmPerPx = kDepthMm / kFocalPx;
    for (const double blur : {0.0, 2.0}) {
        OutlineGrowthOptions options;
        options.blurPx = blur;
        const Scene s = bandScene(3.0, 1.5, {0, 0}, blur);
        const OutlineGrowth g = outlineGrowth(s.baseline, s.current, s.roi, s.featureless, s.plane, RigidTransform{},
                                              s.k, cv::Rect(0, 0, s.roi.cols, s.roi.rows), options);
        ASSERT_GE(g.stations[0], 20) << blur;
        ASSERT_GE(g.stations[1], 20) << blur;
        EXPECT_NEAR(std::min(g.medianMm[0], g.medianMm[1]), -0.4 * 3.0 * mmPerPx, 0.1) << blur;
        EXPECT_NEAR(std::max(g.medianMm[0], g.medianMm[1]), -0.4 * 1.5 * mmPerPx, 0.1) << blur;
        EXPECT_TRUE(g.bothSidesChanged) << blur;
    }
}

TEST(OutlineGrowth, IceOnOneEdgeIsNotALayerOverBoth) {
    const OutlineGrowth g = growthOf(bandScene(4.0, 0.0, {0, 0}), RigidTransform{});
    EXPECT_NEAR(std::min(std::abs(g.medianMm[0]), std::abs(g.medianMm[1])), 0.0, 0.05);
    EXPECT_GT(std::max(std::abs(g.medianMm[0]), std::abs(g.medianMm[1])), 1.0);
    EXPECT_FALSE(g.bothSidesChanged);
}

// The band moved 2.5 px down and 3 px along: with the motion that says so, nothing changed; with
// none (a motion the registration got wrong), one side covers more and the other less. That is no
// layer, but no motion to trust either, and it is caught alike.
TEST(OutlineGrowth, AMovedObjectWithItsMotionDidNotChangeAndWithAWrongOneDid) {
    const Scene s = bandScene(0.0, 0.0, {3.0, 2.5});
    RigidTransform toBaseline;  // current -> baseline: back by the shift on the plane
    toBaseline.translation = {-3.0 * kDepthMm / kFocalPx, -2.5 * kDepthMm / kFocalPx, 0.0};
    const OutlineGrowth moved = growthOf(s, toBaseline);
    ASSERT_GE(moved.stations[0], 20);
    ASSERT_GE(moved.stations[1], 20);
    EXPECT_NEAR(moved.medianMm[0], 0.0, 0.05);
    EXPECT_NEAR(moved.medianMm[1], 0.0, 0.05);
    EXPECT_FALSE(moved.bothSidesChanged);
    const OutlineGrowth unregistered = growthOf(s, RigidTransform{});
    // The texture beside the edge, not moved back, adds its own to each side's reading.
    EXPECT_NEAR(unregistered.medianMm[0] + unregistered.medianMm[1], 0.0, 0.25);
    EXPECT_NEAR(std::abs(unregistered.medianMm[0]), 2.5 * kDepthMm / kFocalPx, 0.25);
    EXPECT_TRUE(unregistered.bothSidesChanged);
}

TEST(OutlineGrowth, AgainstATableNothingIsMeasured) {
    Scene s = bandScene(3.0, 3.0, {0, 0});
    s.featureless.setTo(0);
    const OutlineGrowth g = growthOf(s, RigidTransform{});
    EXPECT_EQ(g.stations[0] + g.stations[1], 0);
    EXPECT_FALSE(g.bothSidesChanged);
}

}  // namespace
}  // namespace icewatch::volume
