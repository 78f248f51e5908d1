#include "core/volume/motion_evidence.hpp"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

namespace icewatch::volume {
namespace {

// A blade lying on a table 850 mm away, seen from straight above: its samples every 10 mm over
// 800 x 100 mm, the table's beside it, 10 mm further. Stereo sees depth worse than position:
// σ 0.03 mm across the view and 0.5 mm along it.
struct BladeOnATable {
    std::vector<TextureTrack> tracks;
    PlaneFrame plane;
    BladeOnATable() {
        std::vector<cv::Vec3d> blade;
        const cv::Matx33d covariance(0.03 * 0.03, 0, 0, 0, 0.03 * 0.03, 0, 0, 0, 0.5 * 0.5);
        auto add = [&](const cv::Vec3d& at, bool onObject) {
            TextureTrack t;
            t.onObject = onObject;
            t.state = TextureTrack::State::Unchanged;
            t.baselineMm = t.currentMm = at;
            t.covarianceMm2 = covariance;
            tracks.push_back(t);
            if (onObject) blade.push_back(at);
        };
        for (double u = -400; u <= 400; u += 10) {
            for (double v = -50; v <= 50; v += 10) add({u, v, 850.0}, true);
            for (double v : {-150.0, -120.0, -90.0, 90.0, 120.0, 150.0}) add({u, v, 860.0}, false);
        }
        plane = fitPlane(blade);
    }
    // Each sample's measurement noise, the same for every test.
    void addNoise() {
        cv::RNG rng(7);
        for (TextureTrack& t : tracks) t.currentMm += cv::Vec3d(rng.gaussian(0.03), rng.gaussian(0.03), rng.gaussian(0.5));
    }
};

// A clear glaze over the whole blade, which did not move: the texture seen through it rose with
// the glaze, 1-4 mm, and a wet glaze's highlights moved where each patch was found a little aside
// (0.1-0.3 mm, several σ, but far less than the rise). The table says the blade did not move.
TEST(MotionEvidence, AClearLayerThatRoseAndMovedTheTextureALittleAsideIsNotTheObjectsMotion) {
    BladeOnATable scene;
    cv::RNG rng(11);
    for (TextureTrack& t : scene.tracks) {
        if (!t.onObject) continue;
        const double rise = rng.uniform(1.0, 4.0), aside = rng.uniform(0.1, 0.3), angle = rng.uniform(0.0, 2 * CV_PI);
        t.currentMm += rise * scene.plane.normal + aside * (std::cos(angle) * scene.plane.axisU + std::sin(angle) * scene.plane.axisV);
    }
    scene.addNoise();
    const MotionEstimate motion = estimateMotion(scene.tracks, scene.plane);
    ASSERT_TRUE(motion.ok) << motion.reason;
    EXPECT_EQ(motion.source, "background");
    EXPECT_LT(cv::norm(motion.transform.apply(scene.plane.origin) - scene.plane.origin), 0.1);
}

// The blade pushed 2 mm along its table: it moved against its background, within its plane, and
// its own texture says how.
TEST(MotionEvidence, AnObjectPushedAlongItsTableMovedAgainstIt) {
    BladeOnATable scene;
    for (TextureTrack& t : scene.tracks)
        if (t.onObject) t.currentMm += 2.0 * scene.plane.axisU;
    scene.addNoise();
    const MotionEstimate motion = estimateMotion(scene.tracks, scene.plane);
    ASSERT_TRUE(motion.ok) << motion.reason;
    EXPECT_EQ(motion.source, "object");
    // current -> baseline: back by the push.
    const cv::Vec3d pushed = scene.plane.origin + 2.0 * scene.plane.axisU;
    EXPECT_LT(cv::norm(motion.transform.apply(pushed) - scene.plane.origin), 0.05);
}

// A blade against the sky (its background tracks nothing) moved 2 mm along its chord, every
// sample found again with its look: the light on the sky did not change, the texture brightened
// by `brightness` - 1.
// With `unevenBy`, every other sample brighter and the rest darker by that much.
MotionEstimate movedAgainstTheSky(double brightness, double unevenBy = 0.0) {
    BladeOnATable scene;
    std::erase_if(scene.tracks, [](const TextureTrack& t) { return !t.onObject; });
    int k = 0;
    for (TextureTrack& t : scene.tracks) {
        t.currentMm += 2.0 * scene.plane.axisU;
        t.brightnessRatio = brightness + (k++ % 2 ? unevenBy : -unevenBy);
    }
    scene.addNoise();
    MotionEvidenceOptions options;
    options.lightRatio = 1.0;
    return estimateMotion(scene.tracks, scene.plane, options);
}

// Light scales all the clean texture alike. A thin layer over all of the blade that brightened the
// texture it kept by 3 % (the rest changed more) moves with the layer's surface, not the blade's:
// that texture does not fix the motion, and with nothing else to go by the chain must refuse.
TEST(MotionEvidence, TextureThatKeptItsLookButBrightenedAsAWholeDoesNotFixTheMotion) {
    const MotionEstimate layered = movedAgainstTheSky(1.03);
    EXPECT_FALSE(layered.ok);
    EXPECT_TRUE(layered.objectLightShifted);
    EXPECT_NE(layered.reason.find("brightened by 3 %"), std::string::npos) << layered.reason;
    EXPECT_NE(layered.reason.find("under the baseline's light"), std::string::npos) << layered.reason;
    const MotionEstimate clean = movedAgainstTheSky(1.005);
    ASSERT_TRUE(clean.ok) << clean.reason;
    EXPECT_EQ(clean.source, "object");
}

// A glaze with wet highlights over all of the blade leaves some texture looking unchanged, some a
// little brighter, some a little darker: its median stays with the light, its spread does not.
TEST(MotionEvidence, TextureThatKeptItsLookButChangedUnevenlyDoesNotFixTheMotion) {
    const MotionEstimate layered = movedAgainstTheSky(1.0, 0.015);
    EXPECT_FALSE(layered.ok);
    EXPECT_TRUE(layered.objectLightShifted);
    EXPECT_NEAR(layered.objectLightSpread, 0.03, 1e-3);
    EXPECT_NE(layered.reason.find("unevenly"), std::string::npos) << layered.reason;
    const MotionEstimate shaded = movedAgainstTheSky(1.0, 0.001);
    ASSERT_TRUE(shaded.ok) << shaded.reason;
    EXPECT_EQ(shaded.source, "object");
}

// Where nothing but the object's texture fixes its motion, less unevenness suffices to refuse: a
// clear glaze whose brightening a dimmed sun cancelled spreads the texture it kept by half a
// percent, clean texture under light by a tenth. With a table that agrees, the same texture is fine.
TEST(MotionEvidence, TextureAloneAgainstTheSkyMustKeepItsLightEvenly) {
    const MotionEstimate alone = movedAgainstTheSky(1.0, 0.003);
    EXPECT_FALSE(alone.ok);
    EXPECT_FALSE(alone.objectLightShifted) << "within the bound for texture that a background backs";
    EXPECT_NEAR(alone.objectLightSpread, 0.006, 1e-3);
    EXPECT_NE(alone.reason.find("where the object alone fixes its motion"), std::string::npos) << alone.reason;

    BladeOnATable scene;  // unmoved, on its table
    int k = 0;
    for (TextureTrack& t : scene.tracks)
        if (t.onObject) t.brightnessRatio = 1.0 + (k++ % 2 ? 0.003 : -0.003);
    scene.addNoise();
    MotionEvidenceOptions options;
    options.lightRatio = 1.0;
    const MotionEstimate backed = estimateMotion(scene.tracks, scene.plane, options);
    ASSERT_TRUE(backed.ok) << backed.reason;
    EXPECT_EQ(backed.source, "object+background");
}

}  // namespace
}  // namespace icewatch::volume
