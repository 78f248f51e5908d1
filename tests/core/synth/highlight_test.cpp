// Highlights: where each eye sees a glossy surface mirror the light, against the law of reflection.
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "core/synth/geometry.hpp"
#include "core/synth/highlight.hpp"

namespace icewatch::synth {
namespace {

constexpr double kDepthMm = 850.0;
constexpr double kBaselineMm = 60.0;

// A flat ice face, facing the camera at kDepthMm, 400 mm square in 1 mm steps, lit from `light`.
Mesh glossyFace(const cv::Vec3d& light) {
    Look look;
    look.towardsLight = cv::normalize(light);
    Mesh mesh;
    mesh.material = kMaterialIceBlock;
    const Pose pose{cv::Matx33d::eye(), {0.0, 0.0, kDepthMm}};
    addQuad(mesh, pose, {-200.0, -200.0, 0.0}, {400.0, 0.0, 0.0}, {0.0, 400.0, 0.0}, 400, look);
    return mesh;
}

// Where the highlight an eye sees peaks on the face.
cv::Vec3d highlightPeak(const Mesh& face, double eyeXMm) {
    Mesh seen = face;
    addHighlights(seen, eyeXMm, IceKind::GlazeAll, 1.0);
    const auto peak = std::max_element(seen.attributes.begin(), seen.attributes.end(),
                                       [](const VertexAttributes& a, const VertexAttributes& b) {
                                           return a[kAttributeHighlight] < b[kAttributeHighlight];
                                       });
    EXPECT_NEAR((*peak)[kAttributeHighlight], 1.0, 1e-3);  // the glaze mirrors all of `gloss` there
    return seen.vertices[static_cast<std::size_t>(peak - seen.attributes.begin())];
}

TEST(Highlight, EachEyeSeesAFlatFaceMirrorTheLightWhereTheLawOfReflectionSays) {
    // A flat mirror sends the light along one direction: each eye sees it where the reflected ray
    // from the light meets that eye, so the two highlights lie a baseline apart on the face, and
    // stereo would match them at infinity, not on the face.
    const cv::Vec3d light = cv::normalize(cv::Vec3d(-0.1, -0.15, -1.0));
    const Mesh face = glossyFace(light);
    const double reach = kDepthMm / -light[2];  // from the face to the eye's plane along the reflection
    for (const double eyeX : {0.0, kBaselineMm}) {
        const cv::Vec3d peak = highlightPeak(face, eyeX);
        EXPECT_NEAR(peak[0], eyeX + reach * light[0], 1.0) << "eye at x = " << eyeX;
        EXPECT_NEAR(peak[1], reach * light[1], 1.0) << "eye at x = " << eyeX;
    }
}

TEST(Highlight, RimeTheTableAndThePlateAreMatteTheGlazeAndTheCoatAreNot) {
    EXPECT_LT(surfaceGloss(kMaterialBlade, IceKind::Patches, 5.0, 1.0).strength, 1e-6);  // covers the coat
    EXPECT_EQ(surfaceGloss(kMaterialTable, IceKind::GlazeAll, 0.0, 1.0).strength, 0.0);
    EXPECT_EQ(surfaceGloss(kMaterialPlate, IceKind::LeadingEdge, 0.0, 1.0).strength, 0.0);
    const Gloss coat = surfaceGloss(kMaterialBlade, IceKind::GlazeAll, 0.0, 1.0);
    const Gloss glaze = surfaceGloss(kMaterialBlade, IceKind::GlazeAll, 3.0, 1.0);
    EXPECT_GT(coat.strength, 0.0);
    EXPECT_GT(glaze.strength, coat.strength);
    EXPECT_GT(glaze.exponent, coat.exponent);  // smoother: a smaller, sharper highlight
    EXPECT_EQ(surfaceGloss(kMaterialBlade, IceKind::GlazeAll, 3.0, 0.0).strength, 0.0);
}

TEST(Highlight, AMatteSceneHasNone) {
    Mesh seen = glossyFace({0.0, 0.0, -1.0});
    addHighlights(seen, 0.0, IceKind::GlazeAll, 0.0);
    for (const VertexAttributes& a : seen.attributes) ASSERT_EQ(a[kAttributeHighlight], 0.0f);
}

}  // namespace
}  // namespace icewatch::synth
