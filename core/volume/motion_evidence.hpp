#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/volume/height_grid.hpp"
#include "core/volume/rigid_motion.hpp"
#include "core/volume/texture_tracks.hpp"

namespace icewatch::volume {

struct MotionEvidenceOptions {
    RigidMotionOptions fit;
    int minPairs = 12;                 // unchanged samples a motion may rest on
    double minSupportSpanPercent = 25; // of the object's extent along both in-plane axes (registration.hpp)
    // A background sample is a surface the object may be fixed to (a table, a rig): within this
    // depth of the object's plane. Farther ones (a distant wall) say how the camera moved, not
    // whether the object moved against them, and are not used.
    double backgroundBandMm = 400;
    // The object's samples agree with a motion when at least this share of them are its inliers.
    double agreeShare = 0.7;
    int jackknifeGroups = 6;
    // The scene's change of light (the background's brightness ratio, background_light.hpp), when
    // known. Light scales the radiance of all the object's clean texture alike: when the median
    // brightness ratio of its unchanged samples departs from the light's by more than
    // maxEvidenceLightShift, the samples that kept their look are the faintest-changed part of a
    // thin layer over the whole object (or the light fell on the object alone), and their motion
    // is not the object's. Half of a single sample's allowance (TextureTrackOptions::
    // maxBrightnessChange, 4 %): a median is far less noisy than a sample.
    std::optional<double> lightRatio;
    double maxEvidenceLightShift = 0.02;
    // Nor when they changed their brightness unevenly: the middle half of their ratios spread over
    // more than this share of the median. Clean texture under any change of light that leaves its
    // look spreads by 0.04-0.35 % (rendered: still, moved, light at 0.85, the sun turned 20°); a
    // glaze over everything that left some texture looking unchanged, by 1.3-3.0 % (with wet
    // highlights against the sky, unmoved: 184 such samples, and -81 % read as ok within
    // +-56 189 mm3). A sun turned 45° spreads it by 2.3 %, and is refused with it: against a
    // featureless sky light on the object alone and a layer over it are not told apart.
    double maxEvidenceLightSpread = 0.01;
    // Tighter where the object's texture alone must fix its motion (no background agrees with it,
    // as against a featureless sky): a clear glaze whose brightening a dimmed sun cancelled kept
    // its median within 1.2 % of the sky's light and spread by 0.54 and 0.99 % (rendered, seeds 14
    // and 114 under the sun at 0.75 and 0.7), and the fit took its surface for the blade's
    // motion: -92 and -89 % as ok. Clean texture moved against the sky spread by 0.03-0.28 % over
    // blur, tone curves, gloss, a low sun, drifting clouds, JPEG 60, noise 4.5 and light 0.8-1.2,
    // glossy and moved far by up to 0.33 % (ridges with gloss 0.24 moved far: 0.47 %, refused);
    // a sun that turned spreads it by up to 0.46 % and brightens or darkens it beyond
    // maxEvidenceLightShift as well. Set from Parameters::maxObjectAloneLightSpreadPercent.
    double maxObjectAloneLightSpread = 0.004;
};

// How the object moved between the captures, and from what evidence.
struct MotionEstimate {
    bool ok = false;
    std::string reason;          // why the motion is not observable
    // The median brightness ratio of the object's unchanged samples over the light's, less 1 (0
    // when the light is not known), their spread, and whether either is beyond its bound: then that
    // texture is not the object's motion (and a refusal says so).
    double objectLightShift = 0;
    double objectLightSpread = 0;  // the interquartile range of those ratios over their median
    bool objectLightShifted = false;  // beyond either bound
    std::string source;          // "object", "background", "object+background"
    RigidTransform transform;    // current -> baseline
    cv::Matx66d covariance = cv::Matx66d::zeros();
    int objectEvidence = 0;      // unchanged object samples the motion agrees with
    int backgroundEvidence = 0;  // unchanged background samples it rests on
    double supportSpanPercent = 0;
    double chi2PerDof = 0;
    // Per track: the sample is unchanged and moved as the object did (clean surface). Object
    // samples that are not are where the ice may be.
    std::vector<std::uint8_t> clean;
    // The motion refitted without each of `jackknifeGroups` bands of the evidence along the
    // object's long axis, as left perturbations of `transform` (rotation vector, translation):
    // their spread shows what the covariance does not, a motion leaning on one end of the object
    // or on evidence that is not quite rigid.
    std::vector<cv::Vec6d> jackknife;
};

// Ice only adds material on the side facing the camera and changes or hides the texture it
// covers; so the motion is taken only from texture that was found again unchanged, in both eyes
// (texture_tracks.hpp), on the object and on a background it may be fixed to:
//   - the object's own unchanged texture, when it spans enough of the object (a tilt fitted on a
//     patch at one end would be extrapolated over the rest);
//   - the background's, when the object's samples move with it (they then share one fit) or when
//     the object has too little unchanged texture but what it has moves with the background;
//   - when the object's unchanged texture and its background disagree, the object moved against
//     its background unless its samples, seen with the background's motion, stayed or rose along
//     the object's normal (aside by less than they rose): that is what a clear layer of ice that
//     kept the texture looks like, and the background is taken.
// Not observable (refused with the reason): too little unchanged texture on the object and no
// background it moves with. The object's own texture does not suffice either when, as a whole, it
// brightened or darkened against the scene's light (MotionEvidenceOptions::lightRatio), or changed
// its brightness unevenly (MotionEvidenceOptions::maxEvidenceLightSpread; where no background
// agrees and the object's texture alone would fix the motion, maxObjectAloneLightSpread).
MotionEstimate estimateMotion(const std::vector<TextureTrack>& tracks, const PlaneFrame& plane,
                              const MotionEvidenceOptions& options = {});

}  // namespace icewatch::volume
