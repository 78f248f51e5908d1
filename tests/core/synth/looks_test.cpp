// The renderer's variety: ice kinds, motion, background, light change and the seed's look, each
// changing the truth exactly as the geometry says.
#include <cmath>
#include <functional>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "core/common/error.hpp"
#include "core/common/side_by_side.hpp"
#include "core/synth/scene.hpp"

namespace icewatch::synth {
namespace {

SceneSpec smallBlade(IceKind ice, MotionKind motion = MotionKind::Small, Background background = Background::Sky) {
    SceneSpec spec;
    spec.iceVolumeMm3 = 97609;
    spec.frameSize = {640, 240};
    spec.supersampling = 2;
    spec.noiseSigma = 0;
    spec.jpegQuality = 100;
    spec.ice = ice;
    spec.motion = motion;
    spec.background = background;
    return spec;
}

cv::Mat leftGrey(const cv::Mat& frame) {
    cv::Mat grey, out;
    cv::cvtColor(splitSideBySide(frame).left, grey, cv::COLOR_BGR2GRAY);
    grey.convertTo(out, CV_32F);
    return out;
}

// Zero-mean normalised correlation of a and b over mask.
double correlation(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask) {
    cv::Scalar meanA, sdA, meanB, sdB;
    cv::meanStdDev(a, meanA, sdA, mask);
    cv::meanStdDev(b, meanB, sdB, mask);
    const cv::Mat product = (a - meanA[0]).mul(b - meanB[0]);
    return cv::mean(product, mask)[0] / (sdA[0] * sdB[0]);
}

// Fine texture: what is left after a 7x7 box blur.
cv::Mat detail(const cv::Mat& grey) {
    cv::Mat blurred;
    cv::blur(grey, blurred, {7, 7});
    return grey - blurred;
}

// How the blade's texture changed between the captures, inside it (eroded off its outline).
struct TextureChange {
    double correlation = 0;  // of the fine texture
    double detailBefore = 0, detailAfter = 0;  // its standard deviation
    double meanBefore = 0, meanAfter = 0;      // grey level
};

TextureChange textureChange(const SyntheticScene& scene) {
    const cv::Mat object = scene.afterDisparity > 0;
    const cv::Mat before = leftGrey(scene.before), after = leftGrey(scene.after);
    cv::Mat inside;
    cv::erode(object & (scene.beforeDisparity > 0), inside, cv::Mat(), {-1, -1}, 3);
    TextureChange c;
    c.correlation = correlation(detail(before), detail(after), inside);
    cv::Scalar mean, sdBefore, sdAfter;
    cv::meanStdDev(detail(before), mean, sdBefore, inside);
    cv::meanStdDev(detail(after), mean, sdAfter, inside);
    c.detailBefore = sdBefore[0];
    c.detailAfter = sdAfter[0];
    c.meanBefore = cv::mean(before, inside)[0];
    c.meanAfter = cv::mean(after, inside)[0];
    return c;
}

TEST(SynthLooks, EveryIceKindCarriesExactlyTheRequestedVolume) {
    for (const IceKind ice :
         {IceKind::LeadingEdge, IceKind::GlazeAll, IceKind::Patches, IceKind::Bead, IceKind::BeadGlaze, IceKind::Ridges,
          IceKind::Shed}) {
        for (const double volume : {97609.0, 257391.0}) {
            SceneSpec spec = smallBlade(ice);
            spec.iceVolumeMm3 = volume;
            spec.frameSize = {128, 48};  // the volume comes from the geometry, not from the pixels
            spec.supersampling = 1;
            const SyntheticScene scene = renderScene(spec);
            // To the precision of the float thickness the meshes carry: a shed sheet is one
            // thickness everywhere, so its rounding does not average out.
            EXPECT_NEAR(scene.iceVolumeMm3, volume, 1e-7 * volume) << iceKindName(ice);
            EXPECT_GT(scene.maxIceThicknessMm, 0.0);
        }
    }
}

// A bead sits on the leading edge, which is the outline: the iced blade stands out of the clean
// one there (ice with sky behind it before), and nowhere far from the edge is iced unless the
// glaze is there too.
TEST(SynthLooks, ABeadStandsOutOfTheCleanOutlineAndTheGlazeCoversTheRest) {
    for (const IceKind ice : {IceKind::Bead, IceKind::BeadGlaze}) {
        const SyntheticScene scene = renderScene(smallBlade(ice, MotionKind::None));
        const cv::Mat before = scene.beforeDisparity > 0, after = scene.afterDisparity > 0;
        const int outside = cv::countNonZero(after & ~before);
        EXPECT_GT(outside, 100) << iceKindName(ice);
        // Ice only adds: at most a pixel astride the outline, whose samples the glaze's rise moved.
        EXPECT_LE(cv::countNonZero(before & ~after), 4) << iceKindName(ice);
        // Inside the clean outline, away from its edges: bare composite, or only the thin glaze.
        cv::Mat inner;
        cv::erode(before, inner, cv::Mat(), {-1, -1}, 4);
        ASSERT_GT(cv::countNonZero(inner), 300);
        double minIce = 0, maxIce = 0;
        cv::minMaxLoc(scene.afterIceMm, &minIce, &maxIce, nullptr, nullptr, inner);
        if (ice == IceKind::Bead) EXPECT_EQ(minIce, 0.0);
        else EXPECT_GT(minIce, 0.0);
        EXPECT_LT(cv::mean(scene.afterIceMm, inner)[0], 0.3 * scene.maxIceThicknessMm) << iceKindName(ice);
    }
}

// Runback ridges are narrow and steep: little of the blade is iced, and what is stands millimetres
// high, with clean surface beside it (the case a matcher's window smears).
TEST(SynthLooks, RidgesAreNarrowSteepBandsWithCleanSurfaceBeside) {
    const SyntheticScene scene = renderScene(smallBlade(IceKind::Ridges, MotionKind::None));
    const cv::Mat object = scene.beforeDisparity > 0;
    const cv::Mat iced = (scene.afterIceMm > 0.05) & object;
    ASSERT_GT(cv::countNonZero(object), 2000);
    const double icedFraction = static_cast<double>(cv::countNonZero(iced)) / cv::countNonZero(object);
    EXPECT_GT(icedFraction, 0.01);
    EXPECT_LT(icedFraction, 0.35);
    EXPECT_GT(scene.maxIceThicknessMm, 2.0);
    // Most of the blade stays bare: the registration has clean texture beside every ridge.
    const cv::Mat clean = (scene.afterIceMm <= 0.0) & object;
    EXPECT_GT(cv::countNonZero(clean), cv::countNonZero(object) / 2);
}

// What shedding leaves: sheets of one thickness, each ending in a sharp step, so that nearly every
// iced pixel carries the full thickness (rime patches taper over the outer 40 % of their radius).
TEST(SynthLooks, ShedIceIsSheetsOfOneThicknessEndingInSharpSteps) {
    const SyntheticScene scene = renderScene(smallBlade(IceKind::Shed, MotionKind::None));
    const cv::Mat object = scene.beforeDisparity > 0;
    const cv::Mat iced = (scene.afterIceMm > 0.0) & object;
    ASSERT_GT(cv::countNonZero(iced), 200);
    const cv::Mat full = (scene.afterIceMm > 0.9 * scene.maxIceThicknessMm) & object;
    EXPECT_GT(cv::countNonZero(full), 0.8 * cv::countNonZero(iced));
    EXPECT_GT(cv::countNonZero((scene.afterIceMm <= 0.0) & object), cv::countNonZero(object) / 3);
}

TEST(SynthLooks, GlazeCoversTheWholeBladeThinlyAndLetsItsTextureThrough) {
    const SyntheticScene scene = renderScene(smallBlade(IceKind::GlazeAll, MotionKind::None));
    const cv::Mat object = scene.afterDisparity > 0;
    ASSERT_GT(cv::countNonZero(object), 2000);
    EXPECT_EQ(cv::countNonZero(object & (scene.afterIceMm <= 0)), 0);  // trailing edge, root and tip too
    double minIce = 0, maxIce = 0;
    cv::minMaxLoc(scene.afterIceMm, &minIce, &maxIce, nullptr, nullptr, object);
    EXPECT_GT(minIce, 0.2);
    EXPECT_LT(maxIce, 8.0);  // thin: the volume is spread over the whole blade
    // The composite's texture shows through, whitened and of lower contrast.
    const TextureChange c = textureChange(scene);
    EXPECT_GT(c.correlation, 0.6);
    EXPECT_LT(c.detailAfter, c.detailBefore);
    EXPECT_GT(c.meanAfter, c.meanBefore + 5.0);
}

TEST(SynthLooks, AClearerGlazeKeepsTheTexturesContrastAndBrightensItAsLightWould) {
    SceneSpec spec = smallBlade(IceKind::GlazeAll, MotionKind::None);
    spec.seed = 2;
    ASSERT_TRUE(drawLook(spec.seed).glazeKeepsTexture);
    ASSERT_FALSE(drawLook(1).glazeKeepsTexture);  // the veiling glaze of the test above
    const SyntheticScene scene = renderScene(spec);
    // A gain: the texture's contrast grows with the brightness, the sky's does not change.
    const TextureChange c = textureChange(scene);
    EXPECT_GT(c.correlation, 0.6);
    EXPECT_GT(c.detailAfter, c.detailBefore);
    EXPECT_GT(c.meanAfter / c.meanBefore, 1.03);
    EXPECT_LT(c.meanAfter / c.meanBefore, 1.16);
    const cv::Mat before = leftGrey(scene.before), after = leftGrey(scene.after);
    const cv::Mat object = scene.afterDisparity > 0;
    cv::Mat sky;
    cv::dilate(object | (scene.beforeDisparity > 0), sky, cv::Mat(), {-1, -1}, 6);
    sky = ~sky;
    EXPECT_NEAR(cv::mean(after, sky)[0], cv::mean(before, sky)[0], 0.5);
}

TEST(SynthLooks, RimePatchesAreOpaqueWhiteAndLeaveMostOfTheBladeClean) {
    const SyntheticScene scene = renderScene(smallBlade(IceKind::Patches, MotionKind::None));
    const cv::Mat object = scene.afterDisparity > 0;
    const double iced = cv::countNonZero(object & (scene.afterIceMm > 0)) / double(cv::countNonZero(object));
    EXPECT_GT(iced, 0.03);
    EXPECT_LT(iced, 0.6);
    const cv::Mat before = leftGrey(scene.before), after = leftGrey(scene.after);
    cv::Mat thick;
    cv::erode(object & (scene.afterIceMm > 2.0) & (scene.beforeDisparity > 0), thick, cv::Mat(), {-1, -1}, 2);
    ASSERT_GT(cv::countNonZero(thick), 50);
    // Opaque: the composite's texture is gone under the rime, which has a texture of its own.
    EXPECT_LT(std::abs(correlation(detail(before), detail(after), thick)), 0.3);
    EXPECT_GT(cv::mean(after, thick)[0], cv::mean(before, thick)[0] + 20.0);
}

TEST(SynthLooks, NoMotionLeavesEverythingButTheIceWhereItWas) {
    const SyntheticScene still = renderScene(smallBlade(IceKind::LeadingEdge, MotionKind::None));
    EXPECT_EQ(cv::norm(still.motion.translationMm), 0.0);
    EXPECT_EQ(cv::norm(still.motion.rotationDeg), 0.0);
    const cv::Mat clean = (still.afterIceMm == 0) & (still.beforeDisparity > 0);
    ASSERT_GT(cv::countNonZero(clean), 1000);
    EXPECT_EQ(cv::norm(still.beforeDisparity, still.afterDisparity, cv::NORM_INF, clean), 0.0);
    EXPECT_GT(cv::countNonZero(still.afterIceMm > 0), 100);
    // Small motion moves the clean surface too.
    const SyntheticScene moved = renderScene(smallBlade(IceKind::LeadingEdge, MotionKind::Small));
    const cv::Mat movedClean = (moved.afterIceMm == 0) & (moved.beforeDisparity > 0) & (moved.afterDisparity > 0);
    EXPECT_GT(cv::norm(moved.beforeDisparity, moved.afterDisparity, cv::NORM_INF, movedClean), 0.01);
}

TEST(SynthLooks, TableFillsTheViewAroundTheBladeWithTexture) {
    const SyntheticScene sky = renderScene(smallBlade(IceKind::LeadingEdge));
    const SyntheticScene table = renderScene(smallBlade(IceKind::LeadingEdge, MotionKind::Small, Background::Table));
    // Every pixel sees a surface at a known depth: the truth is valid around the blade too.
    EXPECT_EQ(cv::countNonZero(table.beforeDisparity <= 0), 0);
    EXPECT_EQ(cv::countNonZero(table.afterDisparity <= 0), 0);
    // Around the blade the table lies just behind it: the same depth, give or take the tilt.
    cv::Mat blade = cv::Mat::zeros(table.beforeDisparity.size(), CV_8U), around;
    std::vector<cv::Point> outline;
    for (const auto& p : table.roi) outline.emplace_back(cvRound(p.x), cvRound(p.y));
    cv::fillPoly(blade, std::vector<std::vector<cv::Point>>{outline}, cv::Scalar(255));
    cv::dilate(blade, around, cv::Mat(), {-1, -1}, 16);
    cv::dilate(blade, blade, cv::Mat(), {-1, -1}, 5);  // clear of the outline's own edge
    around &= ~blade;
    const double bladeDisparity = cv::mean(sky.beforeDisparity, sky.beforeDisparity > 0)[0];
    EXPECT_NEAR(cv::mean(table.beforeDisparity, around)[0], bladeDisparity, 0.03 * bladeDisparity);
    // A clearly textured surface where the sky was featureless.
    cv::Scalar mean, sdTable, sdSky;
    cv::meanStdDev(detail(leftGrey(table.before)), mean, sdTable, around);
    cv::meanStdDev(detail(leftGrey(sky.before)), mean, sdSky, around);
    EXPECT_GT(sdTable[0], 2.0);
    EXPECT_GT(sdTable[0], 5.0 * sdSky[0]);
    // The blade's ice is the only ice.
    EXPECT_NEAR(table.iceVolumeMm3, 97609, 1e-6 * 97609);
    EXPECT_EQ(cv::countNonZero((table.afterIceMm > 0) & ~blade), 0);
}

TEST(SynthLooks, BlockOnATableKeepsItsVolume) {
    SceneSpec spec = smallBlade(IceKind::LeadingEdge, MotionKind::Small, Background::Table);
    spec.kind = SceneKind::Block;
    spec.iceVolumeMm3 = 417391;
    const SyntheticScene scene = renderScene(spec);
    EXPECT_DOUBLE_EQ(scene.iceVolumeMm3, 417391);
    EXPECT_EQ(cv::countNonZero(scene.beforeDisparity <= 0), 0);
}

TEST(SynthLooks, LightChangeScalesTheCurrentCaptureOnly) {
    SceneSpec spec = smallBlade(IceKind::LeadingEdge);
    const SyntheticScene normal = renderScene(spec);
    spec.lightChange = 0.7;
    const SyntheticScene darker = renderScene(spec);
    EXPECT_EQ(cv::norm(normal.before, darker.before, cv::NORM_INF), 0.0);
    EXPECT_NEAR(cv::mean(darker.after)[0] / cv::mean(normal.after)[0], 0.7, 0.01);
    // Brighter saturates honestly at 255 instead of wrapping.
    spec.lightChange = 3.0;
    const SyntheticScene bright = renderScene(spec);
    double minGrey = 0;
    cv::minMaxLoc(leftGrey(bright.after), &minGrey);
    EXPECT_GT(minGrey, 150.0);
    EXPECT_GT(cv::countNonZero(leftGrey(bright.after) == 255), 1000);
}

TEST(SynthLooks, TheSunBehindACloudDarkensTheObjectButNotTheSky) {
    SceneSpec spec = smallBlade(IceKind::LeadingEdge, MotionKind::None);
    const SyntheticScene normal = renderScene(spec);
    spec.sunChange = 0.0;  // only the sky's light is left
    const SyntheticScene clouded = renderScene(spec);
    EXPECT_EQ(cv::norm(normal.before, clouded.before, cv::NORM_INF), 0.0);
    const cv::Mat a = leftGrey(normal.after), b = leftGrey(clouded.after);
    // The sky behind is as it was, to the encoding's rounding.
    EXPECT_LE(std::abs(static_cast<int>(a.at<std::uint8_t>(4, 4)) - b.at<std::uint8_t>(4, 4)), 1);
    // The blade keeps its ambient share of the light: darker by the diffuse share, unevenly over
    // its curved surface (the parts facing the sun lose more), never brighter.
    cv::Mat blade = normal.afterDisparity > 0;
    cv::Mat ratio;
    cv::divide(b, a, ratio, 1.0, CV_32F);
    cv::Scalar mean, spread;
    cv::meanStdDev(ratio, mean, spread, blade);
    const Look look = normal.look;
    EXPECT_LT(mean[0], 1.0 - 0.5 * look.diffuse);
    EXPECT_GT(mean[0], look.ambient - 0.05);
    EXPECT_GT(spread[0], 0.005);
    double maxRatio = 0;
    cv::minMaxLoc(ratio, nullptr, &maxRatio, nullptr, nullptr, blade);
    EXPECT_LT(maxRatio, 1.0 + 1e-6);
}

TEST(SynthLooks, SeedsLookDifferentWithinPlausibleRanges) {
    double minContrast = 1, maxContrast = 0, minFeature = 100, maxFeature = 0, minLightX = 1, maxLightX = -1;
    for (std::uint32_t seed = 1; seed <= 30; ++seed) {
        const Look look = drawLook(seed);
        EXPECT_NEAR(cv::norm(look.towardsLight), 1.0, 1e-12);
        EXPECT_LT(look.towardsLight[2], -0.6);  // lit from behind the camera
        EXPECT_GE(look.compositeContrast, 0.025);  // around the first scenes' 0.035
        EXPECT_LE(look.compositeContrast, 0.05);
        EXPECT_GT(look.iceWhiteness, look.compositeAlbedo);
        minContrast = std::min(minContrast, look.compositeContrast);
        maxContrast = std::max(maxContrast, look.compositeContrast);
        minFeature = std::min(minFeature, look.compositeFeatureMm);
        maxFeature = std::max(maxFeature, look.compositeFeatureMm);
        minLightX = std::min(minLightX, look.towardsLight[0]);
        maxLightX = std::max(maxLightX, look.towardsLight[0]);
    }
    EXPECT_GT(maxContrast / minContrast, 1.5);
    EXPECT_GT(maxFeature / minFeature, 1.5);
    EXPECT_GT(maxLightX - minLightX, 0.3);
    // The block's lab rig keeps its lamps; only the blade's light varies.
    EXPECT_EQ(drawLook(7, true).towardsLight, Look{}.towardsLight);
    EXPECT_EQ(drawLook(7, true).compositeContrast, drawLook(7).compositeContrast);
    // And the pictures differ accordingly: the same blade, another seed's look.
    SceneSpec spec = smallBlade(IceKind::LeadingEdge);
    const SyntheticScene one = renderScene(spec);
    spec.seed = 2;
    const SyntheticScene two = renderScene(spec);
    cv::Scalar mean, sdOne, sdTwo;
    cv::meanStdDev(detail(leftGrey(one.before)), mean, sdOne, one.beforeDisparity > 0);
    cv::meanStdDev(detail(leftGrey(two.before)), mean, sdTwo, two.beforeDisparity > 0);
    EXPECT_GT(std::abs(sdOne[0] - sdTwo[0]) / std::max(sdOne[0], sdTwo[0]), 0.1);
}

// Another renderer's look, set instead of the seed's: a strong, fine texture (a speckle pattern)
// carries more detail than the seed's weak composite, a faint one less, and grey ice is darker
// than the seed's white; the geometry, and so the truth, does not change.
TEST(SynthLooks, TheLookCanBeSetInsteadOfTheSeeds) {
    SceneSpec spec = smallBlade(IceKind::LeadingEdge, MotionKind::None);
    const SyntheticScene seeds = renderScene(spec);
    spec.textureContrast = 0.2;
    spec.textureFeatureMm = 2.0;
    const SyntheticScene speckle = renderScene(spec);
    spec.textureContrast = 0.01;
    spec.textureFeatureMm = 0;
    spec.iceWhiteness = 0.6;
    const SyntheticScene faint = renderScene(spec);
    EXPECT_EQ(speckle.look.compositeContrast, 0.2);
    EXPECT_EQ(speckle.look.compositeFeatureMm, 2.0);
    EXPECT_EQ(faint.look.compositeFeatureMm, seeds.look.compositeFeatureMm);
    EXPECT_EQ(faint.look.iceWhiteness, 0.6);
    const TextureChange a = textureChange(seeds), b = textureChange(speckle), c = textureChange(faint);
    EXPECT_GT(b.detailBefore, 3.0 * a.detailBefore);
    EXPECT_LT(c.detailBefore, 0.5 * a.detailBefore);
    EXPECT_EQ(speckle.iceVolumeMm3, seeds.iceVolumeMm3);
    // Where the ice is thick (the horn), grey ice reads darker in the current capture.
    const cv::Mat horn = seeds.afterIceMm > 5.0f;
    ASSERT_GT(cv::countNonZero(horn), 50);
    EXPECT_LT(cv::mean(leftGrey(faint.after), horn)[0], cv::mean(leftGrey(seeds.after), horn)[0] - 20.0);
}

// The sun moved: the current capture's shading changes unevenly over the curved blade (its
// leading edge turns another way than its flat middle), the baseline not at all, the ice not.
TEST(SynthLooks, ALightTurnShadesTheCurrentCaptureUnevenly) {
    SceneSpec spec = smallBlade(IceKind::LeadingEdge, MotionKind::None);
    const SyntheticScene still = renderScene(spec);
    spec.lightTurnDeg = 30;
    const SyntheticScene turned = renderScene(spec);
    EXPECT_EQ(cv::norm(still.before, turned.before, cv::NORM_INF), 0.0);
    EXPECT_DOUBLE_EQ(turned.iceVolumeMm3, still.iceVolumeMm3);
    // The horn along the leading edge faces another way than the blade's flat middle: its shading
    // changes by another factor.
    const cv::Mat before = leftGrey(still.after), after = leftGrey(turned.after);
    cv::Mat object;
    cv::erode(still.afterDisparity > 0, object, cv::Mat(), {-1, -1}, 3);
    const cv::Mat horn = object & (still.afterIceMm > 3.0f), flat = object & (still.afterIceMm <= 0.0f);
    const double hornChange = cv::mean(after, horn)[0] / cv::mean(before, horn)[0];
    const double flatChange = cv::mean(after, flat)[0] / cv::mean(before, flat)[0];
    EXPECT_GT(std::abs(hornChange - flatChange), 0.03);
}

// A roll turns the blade in the image about the view axis: the same ice, the outline slanted.
TEST(SynthLooks, ARollTurnsTheBladeInTheImageWithTheSameIce) {
    SceneSpec spec = smallBlade(IceKind::LeadingEdge);
    const SyntheticScene level = renderScene(spec);
    spec.rollDeg = 25;
    const SyntheticScene rolled = renderScene(spec);
    EXPECT_DOUBLE_EQ(rolled.iceVolumeMm3, level.iceVolumeMm3);
    // The outline's long axis, from its second moments, turned by the roll.
    auto axisDeg = [](const SyntheticScene& scene) {
        const cv::Moments m = cv::moments(cv::Mat(scene.beforeDisparity > 0), true);
        return 0.5 * std::atan2(2 * m.mu11, m.mu20 - m.mu02) * 180.0 / CV_PI;
    };
    EXPECT_NEAR(axisDeg(rolled) - axisDeg(level), 25.0, 3.0);
    // Rolled so far, this close, that it leaves the frame: refused.
    spec.frameSize = {2560, 720};  // a 16:9 eye: the blade's length across it
    spec.distanceMm = 600;
    spec.rollDeg = 45;
    EXPECT_THROW(renderScene(spec), InvalidInput);
}

// Clouds lie as far as the sky: at the same pixel in both eyes; between the captures they drift,
// and the blade, unmoved, stays as it was but for its ice.
TEST(SynthLooks, CloudsDriftInTheSkyAtTheSamePlaceInBothEyes) {
    SceneSpec spec = smallBlade(IceKind::LeadingEdge, MotionKind::None);
    spec.cloudDrift = 0.1;
    const SyntheticScene cloudy = renderScene(spec);
    cv::Mat sky;
    cv::erode(cloudy.beforeDisparity <= 0, sky, cv::Mat(), {-1, -1}, 4);
    cv::Mat leftGreyBefore = leftGrey(cloudy.before), rightGreyBefore;
    cv::cvtColor(splitSideBySide(cloudy.before).right, rightGreyBefore, cv::COLOR_BGR2GRAY);
    rightGreyBefore.convertTo(rightGreyBefore, CV_32F);
    // Away from the blade in both eyes (the right eye sees it shifted by its disparity).
    cv::Mat rightSky;
    cv::erode(cloudy.beforeDisparity <= 0, rightSky, cv::Mat(), {-1, -1}, 40);
    EXPECT_LT(cv::mean(cv::abs(leftGreyBefore - rightGreyBefore), rightSky)[0], 1.0);
    cv::Scalar mean, sd;
    cv::meanStdDev(leftGreyBefore, mean, sd, sky);
    EXPECT_GT(sd[0], 4.0);  // clouds, not an even overcast
    const cv::Mat drifted = cv::abs(leftGrey(cloudy.after) - leftGreyBefore);
    EXPECT_GT(cv::mean(drifted, sky)[0], 2.0);
    const cv::Mat clean = (cloudy.afterDisparity > 0) & (cloudy.afterIceMm <= 0.0f);
    cv::Mat cleanInside;
    cv::erode(clean, cleanInside, cv::Mat(), {-1, -1}, 3);
    EXPECT_LT(cv::mean(drifted, cleanInside)[0], 0.5);
}

TEST(SynthLooks, ImpossibleOptionsAreRefused) {
    // Each breaks one thing in a scene that renders: the refusal is for that thing alone.
    const SceneSpec blade = smallBlade(IceKind::LeadingEdge);
    SceneSpec block = blade;
    block.kind = SceneKind::Block;
    block.iceVolumeMm3 = 20000;
    ASSERT_NO_THROW(renderScene(blade));
    ASSERT_NO_THROW(renderScene(block));
    const std::vector<std::pair<const char*, std::function<void(SceneSpec&)>>> impossible{
        {"light change under 0.2", [](SceneSpec& s) { s.lightChange = 0.1; }},
        {"light change over 3", [](SceneSpec& s) { s.lightChange = 3.5; }},
        {"light turned over 60 degrees", [](SceneSpec& s) { s.lightTurnDeg = 70; }},
        {"rolled past a half turn", [](SceneSpec& s) { s.rollDeg = 200; }},
        {"farther than 1500 mm", [](SceneSpec& s) { s.distanceMm = 2000; }},
        {"clouds drifting over half the image", [](SceneSpec& s) { s.cloudDrift = 0.6; }},
        {"texture contrast over 0.3", [](SceneSpec& s) { s.textureContrast = 0.5; }},
        {"texture features under 0.5 mm", [](SceneSpec& s) { s.textureFeatureMm = 0.1; }},
        {"ice whiter than white", [](SceneSpec& s) { s.iceWhiteness = 1.5; }},
        {"the sun brighter than three times", [](SceneSpec& s) { s.sunChange = 3.5; }},
        {"a table gap of a negative height", [](SceneSpec& s) { s.tableGapMm = -1; }},
        {"a table gap with no table", [](SceneSpec& s) { s.tableGapMm = 5; }},
    };
    for (const auto& [what, breakIt] : impossible) {
        SceneSpec spec = blade;
        breakIt(spec);
        EXPECT_THROW(renderScene(spec), InvalidInput) << what;
    }
    // A block's ice is the block, and its plate and ice have their own look: the blade's ice
    // kind, look and optics would change nothing, so they are refused rather than ignored.
    const std::vector<std::pair<const char*, std::function<void(SceneSpec&)>>> bladeOnly{
        {"rime patches", [](SceneSpec& s) { s.ice = IceKind::Patches; }},
        {"texture contrast", [](SceneSpec& s) { s.textureContrast = 0.2; }},
        {"texture feature size", [](SceneSpec& s) { s.textureFeatureMm = 20; }},
        {"ice whiteness", [](SceneSpec& s) { s.iceWhiteness = 0.6; }},
        {"refractive ice", [](SceneSpec& s) { s.optics = IceOptics::Refractive; }},
        {"a table gap", [](SceneSpec& s) {
             s.background = Background::Table;
             s.tableGapMm = 5;
         }},
    };
    for (const auto& [what, setIt] : bladeOnly) {
        SceneSpec spec = block;
        setIt(spec);
        EXPECT_THROW(renderScene(spec), InvalidInput) << what;
    }
    EXPECT_THROW(parseIceKind("frost"), InvalidInput);
    EXPECT_THROW(parseMotionKind("huge"), InvalidInput);
    EXPECT_THROW(parseBackground("sea"), InvalidInput);
    EXPECT_EQ(parseIceKind(iceKindName(IceKind::GlazeAll)), IceKind::GlazeAll);
}

}  // namespace
}  // namespace icewatch::synth
