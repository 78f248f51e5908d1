// What the eyes see under clear ice: the renderer's refraction against the optics of a flat slab.
#include <cmath>

#include <gtest/gtest.h>

#include "core/synth/refraction.hpp"

namespace icewatch::synth {
namespace {

constexpr double kDepthMm = 850.0;    // of the surface under the ice
constexpr double kBaselineMm = 60.0;  // the HBVCAM's

// One vertex of a flat surface facing the camera at kDepthMm, under `iceMm` of clear ice, at x
// across the image (mm, on the ice's surface); its surface coordinates are the camera's x and y.
Mesh slabVertex(double xMm, double iceMm) {
    Mesh mesh;
    mesh.vertices = {{xMm, 0.0, kDepthMm - iceMm}};
    mesh.attributes = {{0, 0, 1, static_cast<float>(iceMm), static_cast<float>(xMm), 0}};
    ClearLayer layer;
    layer.under = {{xMm, 0.0, kDepthMm}};
    layer.underNormal = {{0, 0, -1}};
    layer.normal = {{0, 0, -1}};
    layer.textureAxes = cv::Matx23d(1, 0, 0, 0, 1, 0);
    layer.textureOrigin = {0, 0, 0};
    mesh.clearLayer = layer;
    return mesh;
}

double seenX(double xMm, double iceMm, double eyeXMm) {
    return seenThroughClearLayer(slabVertex(xMm, iceMm), eyeXMm).attributes[0][kAttributeSeenA];
}

TEST(Refraction, AnEyeLookingAlongTheNormalSeesStraightDown) {
    EXPECT_NEAR(seenX(0.0, 5.0, 0.0), 0.0, 1e-9);
}

TEST(Refraction, ARayBentTowardsTheNormalMeetsTheSurfaceUnderItWhereSnellSays) {
    const double iceMm = 5.0, xMm = 300.0;
    const double tanIn = xMm / (kDepthMm - iceMm);
    const double sinIn = tanIn / std::sqrt(1 + tanIn * tanIn);
    const double sinOut = sinIn / kIceRefractiveIndex;
    const double expected = xMm + iceMm * sinOut / std::sqrt(1 - sinOut * sinOut);
    EXPECT_NEAR(seenX(xMm, iceMm, 0.0), expected, 1e-4);  // attributes are floats
    // Less far than the unbent ray would go: the ice bends it towards the normal.
    EXPECT_LT(seenX(xMm, iceMm, 0.0), xMm + iceMm * tanIn);
}

TEST(Refraction, AStereoPairSeesTheSurfaceUnderClearIceRaisedByAQuarterOfItsThickness) {
    // The left eye looks straight down at x = 0; the right eye sees the same point of the surface
    // under the ice through the ice's surface at some x < 0, found by bisection. Triangulated, the
    // two rays meet (1 − 1/n) of the ice's thickness above that surface, not on the ice.
    const double iceMm = 5.0;
    double lo = -10.0, hi = 10.0;
    for (int i = 0; i < 100; ++i) {
        const double mid = 0.5 * (lo + hi);
        (seenX(mid, iceMm, kBaselineMm) < 0.0 ? lo : hi) = mid;
    }
    const double rightX = 0.5 * (lo + hi);
    const double along = kBaselineMm / (kBaselineMm - rightX);  // the right ray reaches x = 0
    const double apparentDepth = along * (kDepthMm - iceMm);
    const double rise = kDepthMm - apparentDepth;
    EXPECT_NEAR(rise, iceMm * (1.0 - 1.0 / kIceRefractiveIndex), 0.01 * iceMm);
    EXPECT_LT(rise, 0.3 * iceMm);
}

TEST(Refraction, AMeshWithoutAClearLayerOrAVertexWithoutIceIsSeenAsItIs) {
    Mesh opaque = slabVertex(300.0, 5.0);
    opaque.clearLayer.reset();
    EXPECT_EQ(seenThroughClearLayer(opaque, 0.0).attributes[0][kAttributeSeenA], 300.0f);
    EXPECT_EQ(seenX(300.0, 0.0, 0.0), 300.0);
}

}  // namespace
}  // namespace icewatch::synth
