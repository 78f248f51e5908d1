#include "core/volume/chain.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "core/common/error.hpp"
#include "core/synth/scene.hpp"

namespace icewatch::volume {
namespace {

Parameters sgbmParameters(const std::vector<cv::Point2d>& roi) {
    Parameters p;
    p.stereoMethod = stereo::Method::Sgbm;  // available in every build
    p.maxDisparity = 64;
    for (const auto& q : roi) {
        p.roiPolygon.push_back(q.x);
        p.roiPolygon.push_back(q.y);
    }
    return p;
}

synth::SyntheticScene smallBlock(double volumeMm3, std::uint32_t seed) {
    synth::SceneSpec spec;
    spec.kind = synth::SceneKind::Block;
    spec.iceVolumeMm3 = volumeMm3;
    spec.seed = seed;
    spec.frameSize = {1280, 480};
    return synth::renderScene(spec);
}

TEST(VolumeChain, SmallBlockSceneEndToEnd) {
    // One frame per capture at a third of the camera's resolution, SGBM: the hard, quick case. The
    // product averages many frames (CaptureAverage, tools/volume-bench); here the uncertainty must
    // still cover the error, and the error stay within a fifth.
    const synth::SyntheticScene scene = smallBlock(427174, 2);
    VolumeChain chain(scene.calibration, sgbmParameters(scene.roi));
    const Surface baseline = chain.measureSurface(scene.before);
    const Surface current = chain.measureSurface(scene.after);
    const VolumeResult r = chain.estimate(baseline, current);
    ASSERT_TRUE(r.ok) << r.reason;
    const double error = std::abs(r.volumeMm3 - scene.iceVolumeMm3);
    EXPECT_LT(error, 0.2 * scene.iceVolumeMm3) << "measured " << r.volumeMm3 << " truth " << scene.iceVolumeMm3;
    EXPECT_LT(error, r.uncertaintyMm3);
    EXPECT_GT(r.pointsUsed, 10000);
    EXPECT_NEAR(r.meanThicknessMm, r.volumeMm3 / r.areaMm2, 1e-9);
}

TEST(VolumeChain, GateRefusesADarkPair) {
    const synth::SyntheticScene scene = smallBlock(427174, 3);
    VolumeChain chain(scene.calibration, sgbmParameters(scene.roi));
    const Surface baseline = chain.measureSurface(scene.before);
    const cv::Mat dark = scene.after * 0.05;
    const VolumeResult r = chain.estimate(baseline, chain.measureSurface(dark));
    EXPECT_FALSE(r.ok);
    EXPECT_NE(r.reason.find("too dark"), std::string::npos) << r.reason;
    EXPECT_EQ(r.volumeMm3, 0.0);
}

TEST(VolumeChain, GateRefusesAPairWithoutTexture) {
    const synth::SyntheticScene scene = smallBlock(427174, 4);
    VolumeChain chain(scene.calibration, sgbmParameters(scene.roi));
    const Surface baseline = chain.measureSurface(scene.before);
    cv::Mat flat(scene.after.size(), CV_8UC3, cv::Scalar::all(128));
    cv::Mat noise(flat.size(), CV_8UC3);
    cv::randn(noise, 0, 1.5);
    flat += noise;
    const VolumeResult r = chain.estimate(baseline, chain.measureSurface(flat));
    EXPECT_FALSE(r.ok);
    EXPECT_TRUE(r.reason.find("without texture") != std::string::npos ||
                r.reason.find("too few valid disparities") != std::string::npos)
        << r.reason;
}

TEST(VolumeChain, FrameOfAnotherModeIsAnError) {
    const synth::SyntheticScene scene = smallBlock(427174, 5);
    VolumeChain chain(scene.calibration, sgbmParameters(scene.roi));
    EXPECT_THROW(chain.measureSurface(cv::Mat(720, 2560, CV_8UC3, cv::Scalar::all(100))), InvalidInput);
}

}  // namespace
}  // namespace icewatch::volume
