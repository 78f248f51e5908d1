#include "core/synth/scene.hpp"

#include <gtest/gtest.h>

#include "core/common/error.hpp"

namespace icewatch::synth {
namespace {

TEST(SynthScene, BladeCarriesExactlyTheRequestedVolume) {
    SceneSpec spec;
    spec.iceVolumeMm3 = 197717;
    spec.frameSize = {640, 240};
    spec.supersampling = 2;
    const SyntheticScene scene = renderScene(spec);
    EXPECT_NEAR(scene.iceVolumeMm3, 197717, 1e-6 * 197717);
    EXPECT_EQ(scene.before.size(), cv::Size(640, 240));
    EXPECT_EQ(scene.after.type(), CV_8UC3);
    EXPECT_GT(cv::norm(scene.before, scene.after, cv::NORM_L1), 0.0);  // ice and movement show
    ASSERT_GT(scene.roi.size(), 10u);
    for (const auto& p : scene.roi) {
        EXPECT_GT(p.x, 0);
        EXPECT_LT(p.x, 320);
        EXPECT_GT(p.y, 0);
        EXPECT_LT(p.y, 240);
    }
    EXPECT_NEAR(scene.calibration.baselineMm(), 60.0, 1e-9);
}

TEST(SynthScene, SameSeedSameScene) {
    SceneSpec spec;
    spec.kind = SceneKind::Block;
    spec.iceVolumeMm3 = 417391;
    spec.frameSize = {640, 240};
    spec.supersampling = 1;
    const SyntheticScene a = renderScene(spec), b = renderScene(spec);
    EXPECT_EQ(cv::norm(a.after, b.after, cv::NORM_INF), 0.0);
    EXPECT_DOUBLE_EQ(a.iceVolumeMm3, 417391);
}

TEST(SynthScene, RejectsImpossibleSpecs) {
    SceneSpec spec;
    spec.frameSize = {641, 240};
    EXPECT_THROW(renderScene(spec), InvalidInput);
    spec.frameSize = {640, 240};
    spec.iceVolumeMm3 = -1;
    EXPECT_THROW(renderScene(spec), InvalidInput);
    EXPECT_THROW(parseSceneKind("cone"), InvalidInput);
}

}  // namespace
}  // namespace icewatch::synth
