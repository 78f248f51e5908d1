#include "core/volume/registration.hpp"

#include <cmath>

#include "core/volume/height_grid.hpp"

#include <gtest/gtest.h>

#include "tests/core/volume/test_planes.hpp"

namespace icewatch::volume {
namespace {

// A blade-like strip: 800 mm of span, 100 mm of chord, a sample every 5 mm.
std::vector<cv::Vec3d> stripSamples() {
    std::vector<cv::Vec3d> samples;
    for (double u = -400; u <= 400; u += 5)
        for (double v = -50; v <= 50; v += 5) samples.emplace_back(u, v, 0.0);
    return samples;
}

PlaneFrame cameraPlane() {
    PlaneFrame plane;
    plane.origin = {0, 0, 0};
    plane.axisU = {1, 0, 0};
    plane.axisV = {0, 1, 0};
    plane.normal = {0, 0, 1};
    return plane;
}

TEST(Registration, SupportSpanSeesAPatchAtOneEnd) {
    const std::vector<cv::Vec3d> samples = stripSamples();
    std::vector<std::uint8_t> root(samples.size()), everywhere(samples.size(), 1), rearHalf(samples.size());
    for (std::size_t i = 0; i < samples.size(); ++i) {
        root[i] = samples[i][0] < -250;      // the first fifth of the span, whole chord
        rearHalf[i] = samples[i][1] >= 0;    // along the whole span, half the chord
    }
    const RigidTransform identity;
    EXPECT_DOUBLE_EQ(supportSpanPercent(samples, everywhere, identity, cameraPlane()), 100.0);
    EXPECT_DOUBLE_EQ(supportSpanPercent(samples, {}, identity, cameraPlane()), 100.0);
    // Two tenths of the span, and under a third of each chord bin's samples.
    EXPECT_DOUBLE_EQ(supportSpanPercent(samples, root, identity, cameraPlane()), 0.0);
    // Half the chord over the whole span covers every span bin and half the chord bins.
    EXPECT_DOUBLE_EQ(supportSpanPercent(samples, rearHalf, identity, cameraPlane()), 50.0);
}

TEST(Registration, SupportSpanIgnoresScatteredPatches) {
    const std::vector<cv::Vec3d> samples = stripSamples();
    std::vector<std::uint8_t> patches(samples.size());
    for (std::size_t i = 0; i < samples.size(); ++i) {
        const double u = samples[i][0], v = samples[i][1];
        // The root, plus three small patches further out: under a third of their bins' samples.
        patches[i] = u < -250 || (std::abs(v) <= 10 && (std::abs(u) <= 10 || std::abs(u - 150) <= 10 || std::abs(u - 300) <= 10));
    }
    EXPECT_LT(supportSpanPercent(samples, patches, RigidTransform{}, cameraPlane()), 50.0);
}

TEST(Registration, SupportSpanFollowsTheTransform) {
    // Moving the samples does not change the share: both the region and the support move.
    const std::vector<cv::Vec3d> samples = stripSamples();
    std::vector<std::uint8_t> root(samples.size());
    for (std::size_t i = 0; i < samples.size(); ++i) root[i] = samples[i][0] < -250;
    RigidTransform moved;
    moved.translation = {7, -3, 2};
    EXPECT_DOUBLE_EQ(supportSpanPercent(samples, root, moved, cameraPlane()),
                     supportSpanPercent(samples, root, RigidTransform{}, cameraPlane()));
    EXPECT_EQ(supportSpanPercent({}, {}, RigidTransform{}, cameraPlane()), 0.0);
}

TEST(Registration, APixelLookingPastThePlaneHasNoPlaceInTheCurrentCapture) {
    const PlaneFrame ground = test::groundBelowCamera();
    const RigidTransform identity;
    const PixelInCurrent below = planePixelInCurrent({300, 340}, ground, identity, test::kCamera);
    EXPECT_NEAR(below.at.x, 300.0, 1e-9);
    EXPECT_NEAR(below.at.y, 340.0, 1e-9);
    EXPECT_NEAR(below.depthMm, 1000.0, 1e-9);  // 100 mm down at 0.1 mm per mm ahead
    const PixelInCurrent above = planePixelInCurrent({300, 140}, ground, identity, test::kCamera);
    EXPECT_TRUE(std::isnan(above.at.x) && std::isnan(above.at.y) && std::isnan(above.depthMm));
}

}  // namespace
}  // namespace icewatch::volume
