#include "core/synth/scene.hpp"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "core/common/error.hpp"
#include "core/common/side_by_side.hpp"
#include "core/synth/disparity_floor.hpp"

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

TEST(SynthScene, TruthMapsAreTheGeometryTheEyesSee) {
    SceneSpec spec;
    spec.iceVolumeMm3 = 197717;
    spec.frameSize = {1280, 480};
    spec.supersampling = 2;
    spec.noiseSigma = 0;
    spec.jpegQuality = 100;
    const SyntheticScene scene = renderScene(spec);
    const cv::Size eye{640, 480};
    ASSERT_EQ(scene.beforeDisparity.size(), eye);
    ASSERT_EQ(scene.afterIceMm.size(), eye);
    // f·B/Z at about 0.85 m.
    const double focal = scene.calibration.M1.at<double>(0, 0);
    const double meanDisparity = cv::mean(scene.beforeDisparity, scene.beforeDisparity > 0)[0];
    EXPECT_NEAR(meanDisparity, focal * 60.0 / 850.0, 0.05 * meanDisparity);
    // The ice lies where the current capture sees the blade, and nowhere else.
    double maxIce = 0;
    cv::minMaxLoc(scene.afterIceMm, nullptr, &maxIce, nullptr, nullptr, scene.afterDisparity > 0);
    EXPECT_NEAR(maxIce, scene.maxIceThicknessMm, 0.3 * scene.maxIceThicknessMm);
    EXPECT_EQ(cv::countNonZero((scene.afterIceMm > 0) & (scene.afterDisparity < 0)), 0);
    // Warped by its true disparity the right eye lines up with the left: on noiseless images the
    // boxes' best shifts are zero to a few hundredths of a pixel, so the truth is what the images show.
    for (const cv::Mat* frame : {&scene.before, &scene.after}) {
        const StereoPair eyes = splitSideBySide(*frame);
        cv::Mat left, right;
        cv::cvtColor(eyes.left, left, cv::COLOR_BGR2GRAY);
        cv::cvtColor(eyes.right, right, cv::COLOR_BGR2GRAY);
        const DisparityFloor f = measureDisparityFloor(left, right, frame == &scene.before ? scene.beforeDisparity
                                                                                           : scene.afterDisparity, 15);
        ASSERT_GE(f.boxes, 10);
        EXPECT_LT(std::abs(f.boxMeanPx), 0.02);
        EXPECT_LT(f.boxSigmaPx, 0.05);
    }
}

// A glaze grown along the normals wraps both edges: the volume is still the one asked for (the
// half-rounds along the edges hold part of it, so the layer is thinner), and the current capture
// sees ice out of the baseline's outline on both long sides.
TEST(SynthScene, AGlazeOverTheEdgesStandsOutOfTheOutlineOnBothSides) {
    SceneSpec spec;
    spec.iceVolumeMm3 = 197717;
    spec.ice = IceKind::GlazeAll;
    spec.motion = MotionKind::None;
    spec.frameSize = {2560, 720};  // the camera's mode: the trailing edge's glaze is 1-3 px wide
    spec.supersampling = 2;
    spec.noiseSigma = 0;
    const SyntheticScene ending = renderScene(spec);
    spec.iceOverEdges = true;
    const SyntheticScene wrapping = renderScene(spec);
    EXPECT_NEAR(wrapping.iceVolumeMm3, 197717, 1e-6 * 197717);
    EXPECT_LT(wrapping.maxIceThicknessMm, 0.95 * ending.maxIceThicknessMm);
    std::vector<cv::Point> polygon;
    for (const cv::Point2d& p : wrapping.roi) polygon.emplace_back(cvRound(p.x), cvRound(p.y));
    cv::Mat outline = cv::Mat::zeros(wrapping.afterIceMm.size(), CV_8U);
    cv::fillPoly(outline, std::vector<std::vector<cv::Point>>{polygon}, cv::Scalar(255));
    auto iceOutside = [&outline](const SyntheticScene& scene, cv::Rect half) {
        const cv::Mat ice = (scene.afterIceMm > 0.2f) & ~outline;
        return cv::countNonZero(ice(half));
    };
    // The blade lies along the image: its leading edge in one half of the rows, its trailing edge
    // in the other.
    const cv::Rect box = cv::boundingRect(polygon);
    const cv::Rect upper(0, 0, outline.cols, box.y + box.height / 2);
    const cv::Rect lower(0, upper.height, outline.cols, outline.rows - upper.height);
    // Beyond the pixels the outline's polygon cuts (which see its edge, ice or not), a row along
    // each edge at least.
    EXPECT_GT(iceOutside(wrapping, upper), iceOutside(ending, upper) + box.width / 2);
    EXPECT_GT(iceOutside(wrapping, lower), iceOutside(ending, lower) + box.width / 2);
    // Only a glaze-all blade's ice is grown that way.
    spec.ice = IceKind::Patches;
    EXPECT_THROW(renderScene(spec), InvalidInput);
}

// How far (mm, on the object's plane at its distance) ice reaches out of the scene's outline, and
// whether any of it lies above the blade (the leading edge's side).
struct IceOutOfOutline {
    double farthestMm = 0;
    int aboveBladePixels = 0;
};

IceOutOfOutline iceOutOfOutline(const SceneSpec& spec, const SyntheticScene& scene) {
    std::vector<cv::Point> polygon;
    for (const cv::Point2d& p : scene.roi) polygon.emplace_back(cvRound(p.x), cvRound(p.y));
    cv::Mat outside(scene.afterIceMm.size(), CV_8U, cv::Scalar(255));
    cv::fillPoly(outside, std::vector<std::vector<cv::Point>>{polygon}, cv::Scalar(0));
    // How far each pixel lies from the outline, and the farthest that shows ice.
    cv::Mat distancePx;
    cv::distanceTransform(outside, distancePx, cv::DIST_L2, 3);
    double farthestPx = 0;
    const cv::Mat iceOutside = (scene.afterIceMm > 0.2f) & outside;
    cv::minMaxLoc(distancePx, nullptr, &farthestPx, nullptr, nullptr, iceOutside);
    const cv::Rect box = cv::boundingRect(polygon);
    return {farthestPx * spec.distanceMm / scene.calibration.rectifiedFocalPx(),
            cv::countNonZero(iceOutside(cv::Rect(0, 0, iceOutside.cols, box.y)))};
}

SceneSpec icicledBlade(double volumeMm3, double lengthScale) {
    SceneSpec spec;
    spec.iceVolumeMm3 = volumeMm3;
    spec.ice = IceKind::Icicles;
    spec.icicleLength = lengthScale;
    spec.motion = MotionKind::None;
    spec.frameSize = {1280, 360};
    spec.supersampling = 2;
    spec.noiseSigma = 0;
    return spec;
}

TEST(SynthScene, IciclesHangOutOfTheTrailingEdgeFartherThanTheChainsRing) {
    const SceneSpec spec = icicledBlade(197717, 1.0);
    const SyntheticScene scene = renderScene(spec);
    EXPECT_NEAR(scene.iceVolumeMm3, 197717, 1e-6 * 197717);
    const IceOutOfOutline out = iceOutOfOutline(spec, scene);
    EXPECT_GT(out.farthestMm, 60.0);  // past volume.outline_growth_mm's 50 mm
    EXPECT_EQ(out.aboveBladePixels, 0);  // all of it below the blade: the trailing edge's side
}

// Stubby icicles hold the same volume within the ring: the chain has to measure them, not refuse
// them for reaching its edge.
TEST(SynthScene, StubbyIciclesHoldTheirVolumeWithinTheChainsRing) {
    const SceneSpec spec = icicledBlade(97609, 0.25);
    const SyntheticScene scene = renderScene(spec);
    EXPECT_NEAR(scene.iceVolumeMm3, 97609, 1e-6 * 97609);
    const IceOutOfOutline out = iceOutOfOutline(spec, scene);
    EXPECT_GT(out.farthestMm, 10.0);  // they still hang out of the outline
    // Short of the last pixels of volume.outline_growth_mm's 50 mm, where ice is refused.
    EXPECT_LT(out.farthestMm, 46.0);
    EXPECT_EQ(out.aboveBladePixels, 0);
    // Only icicles have a length.
    SceneSpec glaze = spec;
    glaze.ice = IceKind::GlazeAll;
    EXPECT_THROW(renderScene(glaze), InvalidInput);
}

// A textured pair with a known whole-pixel shift and independent noise in each eye.
struct ShiftedPair {
    cv::Mat left, right, disparity;
};

ShiftedPair shiftedPair(double noiseSigma, int shift, unsigned seed) {
    cv::RNG rng(seed);
    cv::Mat texture(620, 620 + shift, CV_32F);
    rng.fill(texture, cv::RNG::NORMAL, 128, 30);
    cv::GaussianBlur(texture, texture, {0, 0}, 1.5);
    ShiftedPair p;
    p.left = texture(cv::Rect(0, 0, 620, 620)).clone();       // left x sees texture x
    p.right = texture(cv::Rect(shift, 0, 620, 620)).clone();  // and so does right x - shift
    cv::Mat noise(p.left.size(), CV_32F);
    rng.fill(noise, cv::RNG::NORMAL, 0, noiseSigma);
    p.left += noise;
    rng.fill(noise, cv::RNG::NORMAL, 0, noiseSigma);
    p.right += noise;
    p.disparity = cv::Mat(p.left.size(), CV_32F, cv::Scalar(shift));
    p.disparity.colRange(0, shift + 2).setTo(-1.0f);  // nothing to see in the right eye there
    return p;
}

TEST(DisparityFloor, NoiselessPairHasNone) {
    const ShiftedPair p = shiftedPair(0.0, 7, 1);
    const DisparityFloor f = measureDisparityFloor(p.left, p.right, p.disparity, 31);
    EXPECT_GE(f.boxes, 300);
    EXPECT_LT(f.boxSigmaPx, 1e-4);
    EXPECT_LT(f.residualSigma, 1e-3);
}

TEST(DisparityFloor, FollowsTheCramerRaoBoundOfWhiteNoise) {
    // One shift from N pixels of squared gradient mean(g²), residual noise σ_e: σ = σ_e / sqrt(N·mean(g²)).
    for (const double sigma : {1.0, 4.0}) {
        const ShiftedPair p = shiftedPair(sigma, 7, 2);
        const DisparityFloor f = measureDisparityFloor(p.left, p.right, p.disparity, 31);
        const double bound = sigma * std::sqrt(2.0) / std::sqrt(31.0 * 31.0 * f.meanGradientSq);
        EXPECT_NEAR(f.residualSigma, sigma * std::sqrt(2.0), 0.1 * sigma * std::sqrt(2.0));
        EXPECT_NEAR(f.boxSigmaPx, bound, 0.25 * bound) << "sigma " << sigma;
        EXPECT_NEAR(f.meanSigmaPx(31 * 31 * 100), f.boxSigmaPx / 10.0, 1e-12);
    }
}

TEST(DisparityFloor, RejectsMismatchedInput) {
    const cv::Mat grey(40, 40, CV_8U, cv::Scalar(1));
    const cv::Mat disparity(40, 40, CV_32F, cv::Scalar(1));
    EXPECT_THROW(measureDisparityFloor(grey, grey(cv::Rect(0, 0, 30, 40)), disparity), InvalidInput);
    EXPECT_THROW(measureDisparityFloor(grey, grey, cv::Mat(40, 40, CV_8U)), InvalidInput);
    EXPECT_THROW(measureDisparityFloor(grey, grey, disparity, 3), InvalidInput);
}

}  // namespace
}  // namespace icewatch::synth
