#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "core/volume/patch_tracker.hpp"

namespace icewatch::volume {

// Both captures of one scene, rectified, as the tracker reads them.
struct RectifiedCapture {
    TrackingImage left, right;  // as prepareForTracking (patch_tracker.hpp) made them, over the matched window
    cv::Mat disparity;          // CV_32F left-view disparities from the matcher, frame-sized, < 0 where none
};

struct TextureTrackOptions {
    PatchTrackOptions patch;        // window and refinement of every track
    int stepPx = 12;                // one sample every this many pixels in x and y
    int temporalSearchPx = 8;       // how far (px) a patch may have moved between the captures beyond the prior
    double maxShiftSigmaPx = 0.08;  // a track less precise than this along its worst axis is not evidence
    // No track is taken as more precise than this (px, 1 σ, added to each eye's shift in
    // quadrature): a patch's own residual can be near zero where the images are all but free of
    // noise, and what is left then is the tracker's own error (its bias bar is 0.01 px).
    double minShiftSigmaPx = 0.01;
    double minZncc = 0.6;           // below: the texture was not found again (covered, or changed)
    double offsetSigmas = 4.0;      // an offset beyond this many of its σ, and ...
    double minOffsetShare = 0.04;   // ... beyond this share of the patch's mean, is a change of appearance
    // A patch whose brightness changed by more than this share against the scene's own change
    // (the background's, or the median over every sample found: light scales the scene alike)
    // changed its look.
    double maxBrightnessChange = 0.04;
    // A track found in both eyes but too imprecise to be evidence is a glimpse of its texture when
    // the left patch lies within this of where the image motion puts it. Refraction under a clear
    // layer moves it by a fraction of a pixel; a chance peak in a patch whose texture opaque ice
    // hid lies anywhere in the search (on a rendered ice block 22 of 23 such peaks were not found
    // in the right eye, and most lay 1-8 px off; under a refractive glaze 407 of 469 lay within 1 px).
    double glimpseReachPx = 2.0;
};

// Whether a pixel is one of the baseline's texture samples (before the object's outline picks
// among them): every stepPx pixels in x and y, half a step in from the frame's corner.
inline bool isSamplePixel(int x, int y, int stepPx) {
    return x % stepPx == stepPx / 2 && y % stepPx == stepPx / 2;
}

// Where one baseline texture sample went, in three dimensions.
struct TextureTrack {
    enum class State {
        Untracked,  // no texture to follow, not found again in one of the three tracks, or imprecise
        Changed,    // found, but its appearance changed in a way light does not change it (ice)
        Unchanged,  // found again with the same look: evidence of how the object moved
    };
    cv::Point pixel;          // baseline left rectified pixel
    bool onObject = false;    // inside the object's outline (else background)
    bool inBaseline = false;  // the baseline's own stereo track found it: texture there to follow
    State state = State::Untracked;
    cv::Vec3d baselineMm;     // left rectified camera frame
    cv::Vec3d currentMm;
    double baselineDisparity = 0;  // px, re-measured by the stereo track at `pixel`
    cv::Point2d currentPixel;      // where the left patch was found in the current capture
    double currentDisparity = 0;   // px, there
    cv::Matx33d covarianceMm2 = cv::Matx33d::zeros();  // of currentMm - baselineMm
    double zncc = 0;
    double offsetGrey = 0;    // photometric offset of the left eye's temporal track
    double brightnessRatio = 1;  // of the left eye's temporal track
    // Untracked, yet found again in both eyes (correlation at least minZncc) where the image
    // motion puts it (glimpseReachPx): too imprecise to measure in three dimensions, but its
    // texture still shows. A clear layer veils it and refraction shifts it otherwise in each eye,
    // which is what leaves such a track imprecise; the layer does not hide it, as opaque ice would.
    bool glimpsed = false;
    bool glimpsedLookChanged = false;  // and its look changed (offset, or brightness against the scene's)
};

// The baseline's texture followed into the current capture in both eyes, without the stereo
// matcher's aggregation (which spreads ice over the clean surface around it):
//   1. the baseline's own disparity at each sample, re-measured by a horizontal patch track
//      from its left into its right eye, starting from the matcher's value (baselineSamples);
//   2. the left patch tracked from the baseline to the current left image, the right patch
//      (at the refined disparity) from the baseline to the current right image;
//   3. the current disparity = baseline disparity + left shift - right shift, and both points
//      lifted to 3-D with Q; the covariance follows from the tracks' own covariances.
// Samples lie on a regular grid inside `object` (eroded by the patch radius) and, as background,
// outside it (dilated by the radius), where the baseline has a disparity. Work is split into
// fixed bands of samples, so the result does not depend on the number of threads.

// The left patch at `at` found again along the row in the capture's right eye, from the matcher's
// disparity there (±2 px): the disparity is -shift.x. Not found where the matcher has none.
PatchTrack stereoPatchTrack(const RectifiedCapture& capture, cv::Point at, const TextureTrackOptions& options);

// The samples and step 1, which depend on the baseline alone (a daemon works them out once per
// baseline, BaselineModel): every grid sample and the disparity its stereo track re-measured
// there (NaN where the track found none).
struct BaselineSamples {
    std::vector<cv::Point> pixels;
    std::vector<std::uint8_t> onObject;
    std::vector<double> disparity;
};
BaselineSamples baselineSamples(const RectifiedCapture& baseline, const cv::Mat& object,
                                const TextureTrackOptions& options = {});
// Steps 2 and 3 for the samples whose patch and search the current capture's window holds.
// `imageMotion` is where a baseline pixel is expected in the current capture (image_motion.hpp). `lightRatio`: the scene's
// change of light (background_light.hpp); a patch whose brightness changed otherwise changed its
// look. Without it, the median over every sample found stands in (ice over the whole object then
// passes for light).
std::vector<TextureTrack> trackTexture(const BaselineSamples& samples, const RectifiedCapture& baseline,
                                       const RectifiedCapture& current, const cv::Matx44d& q,
                                       const cv::Matx23d& imageMotion, std::optional<double> lightRatio = std::nullopt,
                                       const TextureTrackOptions& options = {});

}  // namespace icewatch::volume
