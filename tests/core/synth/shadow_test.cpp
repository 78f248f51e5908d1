// Cast shadows: where a caster hides the sun, against the geometry of a ray towards the light, and
// what they do (and do not do) to a rendered scene.
#include <cmath>
#include <utility>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "core/synth/geometry.hpp"
#include "core/synth/scene.hpp"
#include "core/synth/shadow.hpp"

namespace icewatch::synth {
namespace {

constexpr double kDepthMm = 850.0;

// A square 100 mm a side facing the camera, hoverMm nearer than kDepthMm, centred on the axis.
Mesh hoveringSquare(double hoverMm) {
    Mesh mesh;
    mesh.material = kMaterialBlade;
    const Pose pose{cv::Matx33d::eye(), {0.0, 0.0, kDepthMm - hoverMm}};
    addQuad(mesh, pose, {-50.0, -50.0, 0.0}, {100.0, 0.0, 0.0}, {0.0, 100.0, 0.0}, 20, Look{});
    return mesh;
}

TEST(Shadow, ASquareHidesTheSunFromTheGroundWhereTheRayTowardsTheLightMeetsIt) {
    // The sun up and to the left behind the camera: the square's shadow on a ground kDepthMm away
    // is the square moved by hover · (light's x, y) / light's z, away from the light.
    const cv::Vec3d towardsLight = cv::normalize(cv::Vec3d(-0.3, -0.5, -1.0));
    const double hover = 20.0;
    const ShadowMap map({hoveringSquare(hover)}, towardsLight);
    const double dx = hover * towardsLight[0] / towardsLight[2], dy = hover * towardsLight[1] / towardsLight[2];
    EXPECT_EQ(map.lit({dx, dy, kDepthMm}), 0.0f);                  // behind the square's middle
    EXPECT_EQ(map.lit({dx + 45.0, dy - 45.0, kDepthMm}), 0.0f);    // inside its corner
    EXPECT_EQ(map.lit({dx + 55.0, dy, kDepthMm}), 1.0f);           // just past its edge
    EXPECT_EQ(map.lit({dx, dy - 55.0, kDepthMm}), 1.0f);
    // Straight behind the square along the view, the shadow has moved away: the ground is lit.
    EXPECT_EQ(map.lit({-45.0, -45.0, kDepthMm}), 1.0f);
    // The square's own surface, facing the light, is in its light.
    EXPECT_EQ(map.lit({10.0, -20.0, kDepthMm - hover}), 1.0f);
    // And in front of it, nearer the light, nothing is shadowed.
    EXPECT_EQ(map.lit({0.0, 0.0, kDepthMm - hover - 5.0}), 1.0f);
}

TEST(Shadow, NoCasterNoShadow) {
    const ShadowMap map({}, cv::normalize(cv::Vec3d(0.0, 0.0, -1.0)));
    EXPECT_EQ(map.lit({0.0, 0.0, kDepthMm}), 1.0f);
}

TEST(Shadow, ABlockDarkensThePlateBesideItAndChangesNoTruth) {
    SceneSpec spec;
    spec.kind = SceneKind::Block;
    spec.iceVolumeMm3 = 427174.0;
    spec.frameSize = {640, 240};
    spec.noiseSigma = 0.0;
    spec.jpegQuality = 100;  // so that the encoding's ringing does not pass for light
    spec.supersampling = 2;
    const SyntheticScene plain = renderScene(spec);
    spec.shadows = true;
    const SyntheticScene shadowed = renderScene(spec);

    // The geometry and its truth are the same: a shadow is light, not matter.
    EXPECT_EQ(shadowed.iceVolumeMm3, plain.iceVolumeMm3);
    EXPECT_EQ(cv::norm(shadowed.afterDisparity, plain.afterDisparity, cv::NORM_INF), 0.0);
    // The block, 60 mm tall under a light 31° off the view, darkens a band of the plate beside it
    // to the ambient share of the light; nothing gets brighter. The clean baseline has no block,
    // so it has no shadow either.
    auto grey = [](const cv::Mat& bgr) {
        cv::Mat g;
        cv::cvtColor(bgr, g, cv::COLOR_BGR2GRAY);
        return g;
    };
    const cv::Mat darker = (grey(plain.after) - grey(shadowed.after)) > 15;
    const cv::Mat brighter = (grey(shadowed.after) - grey(plain.after)) > 3;
    EXPECT_GT(cv::countNonZero(darker), 200);
    EXPECT_LT(cv::countNonZero(brighter), cv::countNonZero(darker) / 10);
    EXPECT_EQ(cv::countNonZero((grey(plain.before) - grey(shadowed.before)) > 15), 0);
}

TEST(Shadow, ALowSunCastsARaisedBladesShadowOnTheTable) {
    SceneSpec spec;
    spec.frameSize = {640, 240};
    spec.noiseSigma = 0.0;
    spec.jpegQuality = 100;
    spec.supersampling = 2;
    spec.background = Background::Table;
    spec.tableGapMm = 10.0;
    spec.sunAngleDeg = 70.0;
    const SyntheticScene plain = renderScene(spec);
    EXPECT_NEAR(std::acos(-plain.look.towardsLight[2]) * 180.0 / 3.14159265358979323846, 70.0, 1e-9);
    spec.shadows = true;
    const SyntheticScene shadowed = renderScene(spec);
    // 10 mm above the table under a sun 70° off the view, the blade's shadow reaches some 27 mm
    // past its outline: about six pixels of this small eye along the blade, in both captures.
    for (const auto& [a, b] : {std::pair{plain.before, shadowed.before}, std::pair{plain.after, shadowed.after}}) {
        cv::Mat ga, gb;
        cv::cvtColor(a, ga, cv::COLOR_BGR2GRAY);
        cv::cvtColor(b, gb, cv::COLOR_BGR2GRAY);
        EXPECT_GT(cv::countNonZero((ga - gb) > 15), 800);
    }
}

}  // namespace
}  // namespace icewatch::synth
