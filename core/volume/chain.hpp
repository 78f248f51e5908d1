#pragma once

#include <array>
#include <chrono>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "core/calib/stereo_calibration.hpp"
#include "core/common/side_by_side.hpp"
#include "core/stereo/parameters.hpp"
#include "core/volume/image_quality.hpp"
#include "core/volume/match_region.hpp"
#include "core/volume/parameters.hpp"
#include "core/volume/patch_tracker.hpp"
#include "core/volume/baseline_model.hpp"
#include "core/volume/uncertainty.hpp"

namespace icewatch::volume {

// Stage name -> milliseconds, in the order the stages ran.
using Timings = std::vector<std::pair<std::string, double>>;

// One capture measured: everything estimate() needs, so the daemon can keep the baseline's.
struct Surface {
    cv::Mat rectifiedLeft;  // CV_8U grey, rectified left eye (for people and the image checks)
    cv::Mat leftGrey;       // CV_32F grey, rectified, as measured (an averaged capture keeps its fraction)
    // One draw of leftGrey's own noise, rectified as it was (AveragedCapture::noise; CV_32F, zero
    // outside matchedWindow). Empty when the capture had none (a single frame).
    cv::Mat leftNoise;
    TrackingImage trackLeft, trackRight;  // both eyes as the texture trackers read them, over the matched window
    cv::Mat disparity;      // CV_32F, px, stereo::kInvalidDisparity where none (always outside matchedWindow)
    cv::Rect matchedWindow;  // the matcher's window in the frame (VolumeChain::points reads only there)
    cv::Mat roi;            // CV_8U, 255 inside the object's outline (rectified left pixels)
    ImageQuality quality;   // of the left eye inside the region
    double validPercent = 0;  // valid disparities inside the region
    // Where it was matched: an empty box is the whole frame (the band then 0 .. max_disparity).
    MatchRegion matched;
    // Where the captures compared with this one are matched (a baseline's; empty: the whole frame).
    MatchRegion followUp;
    // Why it cannot be compared with the baseline it was matched for (the object left the
    // matched region); empty when it can.
    std::string regionProblem;
    // The region was found by depth, no outline having been drawn (or kept from a baseline's).
    bool roiSegmented = false;
    // Of an outline drawn around the object, the background it held and was left out (drawn_outline.hpp,
    // raised_object.hpp).
    double outlineBackgroundPercent = 0;
    // The scene's shift took the region out of the matched box but the region was not found there
    // either: said beside the registration's reason when it then finds no evidence, unless the
    // object's texture was found again where it was.
    std::string regionHint;
    // The scene's shift from the baseline it was measured against (phase correlation in the
    // baseline's region, px): the region check's and the trackers' start. Empty when measured alone.
    std::optional<cv::Point2d> shiftFromBaselinePx;
    // A baseline's (measured without one): what the estimate needs of it alone, worked out once
    // (baseline_model.hpp). Shared, so that copies of the surface share it too.
    std::shared_ptr<const BaselineModel> model;
    Timings timingsMs;
};

struct VolumeResult {
    bool ok = false;
    std::string reason;  // why it was refused
    double volumeMm3 = 0;
    double uncertaintyMm3 = 0;  // expanded (coverageFactor · σ)
    UncertaintyBudget budget;   // 1-σ parts
    double meanThicknessMm = 0;  // volume / area of the region (what the alarms compare)
    double meanThicknessUncertaintyMm = 0;  // the expanded uncertainty over the same area
    double maxThicknessMm = 0;   // of the locally averaged thickness map
    double areaMm2 = 0;          // of the region on the object's plane
    int pointsUsed = 0;          // current points that built the surface
    double validPercent = 0;     // valid disparities in the region, current capture
    double filledPercent = 0;    // grid area with no measurement, filled from the nearest
    double registrationMm = 0;   // how far the current capture moved the region's centre
    double registrationDeg = 0;  // and turned
    double registrationRmsMm = 0;
    // The registered motion itself, current -> baseline in the baseline's rectified left camera
    // frame (mm): what a field engineer compares with how the blade is known to have moved.
    RigidTransform registration;
    // How the object's unchanged texture changed its brightness against the scene's light (the
    // median ratio less 1) and how unevenly (the middle half's spread over the median): light
    // scales clean texture alike, a thin layer over it does not (motion_evidence.hpp).
    double objectLightShift = 0, objectLightSpread = 0;
    int textureInliers = 0;      // unchanged object texture samples the registration agrees with
    int backgroundInliers = 0;   // unchanged background samples it rests on (0: the object alone)
    std::string registrationSource;  // "object", "background", "object+background"
    int unchangedSamples = 0;    // texture samples found again unchanged (object and background)
    int changedSamples = 0;      // object samples found again with a changed look (ice)
    double supportSpanPercent = 0;  // extent of the unchanged surface the registration rests on
    // How far the outline grew against the sky beyond the registered motion on each long side,
    // mm, and at how many stations it was measured (outline_growth.hpp; none: not against a sky).
    std::array<double, 2> outlineGrowthMm{0.0, 0.0};
    std::array<int, 2> outlineGrowthStations{0, 0};
    // How blurred the captures are, read off the outline or the edge around it (edge_blur.hpp), px; 0: not read.
    double blurPx = 0;
    // Of the pixels where ice was read, the share whose texture along the rows is too faint for
    // stereo to tell their depth (row_texture.hpp), %.
    double faintIcePercent = 0;
    // The region's texture in the baseline and the current capture (image_quality.hpp: contrast).
    double baselineContrast = 0, currentContrast = 0;
    double iceAreaMm2 = 0;       // where thickness was integrated: possible ice, grown by the matcher's reach
    double beyondOutlineMm3 = 0, beyondOutlineAreaMm2 = 0;  // of that, ice standing out of the outline
    // Ice the object's texture was seen through (seen_through.hpp), as the matcher read it. The
    // volume holds the middle of what such ice may be (that to n/(n − 1) times it), the budget the rest.
    double seenThroughMm3 = 0;
    double glimpsedThroughMm3 = 0;  // read where the texture was only glimpsed through ice (seen_through.hpp)
    double iceMaskPercent = 0;   // of the region
    double outlineBackgroundPercent = 0;  // of the drawn outline, background left out of the region
    double matcherPushPx = 0;    // the matcher's change against the tracks' on clean texture (matcher_push.hpp)
    double matcherPushSigmaPx = 0;  // and its standard error
    Timings timingsMs;

    // For people (core/pictures draws them): the thickness where it lies in the current rectified
    // left eye (CV_32F, mm, NaN where not measured), the current cloud in the baseline's frame
    // with its thickness.
    cv::Mat thicknessImageMm;
    std::vector<cv::Vec3f> cloudMm;
    std::vector<float> cloudThicknessMm;
};

// The volume chain: split → rectify → match → reproject (measureSurface), then register →
// filter → grid → integrate → seen through → uncertainty → gate (estimate). Not thread-safe (one matcher).
class VolumeChain {
public:
    using Clock = std::function<std::chrono::steady_clock::time_point()>;

    // Throws Error(kExitConfig) on parameters it cannot use; `clock` times the stages (none: 0 ms).
    // `stereoParameters`: the matcher's (the configuration's "stereo" section).
    VolumeChain(const calib::StereoCalibration& calibration, const Parameters& parameters, Clock clock = {},
                const stereo::Parameters& stereoParameters = {});
    ~VolumeChain();
    VolumeChain(VolumeChain&&) noexcept;
    VolumeChain& operator=(VolumeChain&&) noexcept;

    // A side-by-side camera frame or an unrectified pair, measured as a baseline. The frame is
    // taken by value: a caller that moves it in gives the chain the only reference, and its
    // memory (17 MB of float average at 3840x1080) goes back as soon as the eyes are rectified,
    // before the matcher takes its buffers. The region is the
    // configured polygon, or segmented from this capture when there is none. With a polygon the
    // capture is matched only around it (a coarse pass finds the band first, match_region.hpp);
    // without one over the whole frame and every disparity. Either way the surface's followUp says
    // where later captures are matched. Throws InvalidInput when the frame does not fit the
    // calibration.
    // An averaged capture's noise draw (AveragedCapture::noise, the frame's layout), when given, is
    // rectified with it and kept (Surface::leftNoise): what reads texture takes it off. Taken by
    // value as the frame is, and let go before the match.
    Surface measureSurface(cv::Mat sideBySideFrame, cv::Mat sideBySideNoise = {});
    Surface measureSurface(StereoPair raw, StereoPair rawNoise = {});
    // A capture to compare with `baseline`: rectified and matched only in the baseline's followUp
    // region and band (the whole frame when it has none). The surface keeps the frame's size,
    // its disparity invalid outside the matched box.
    Surface measureSurface(cv::Mat sideBySideFrame, const Surface& baseline, cv::Mat sideBySideNoise = {});
    Surface measureSurface(StereoPair raw, const Surface& baseline, StereoPair rawNoise = {});

    // A surface's points, [X Y Z] = Q·[x y d 1] (mm, left rectified camera frame; CV_32FC3, NaN
    // where there is no disparity). Computed on demand rather than kept in the Surface: a frame
    // of them is 25 MB at 1920x1080 per eye, and only the estimate reads them, after the matcher
    // has given its buffers back.
    cv::Mat points(const Surface& surface) const;

    // The ice between a baseline (clean) and a current surface, inside the baseline's region.
    // A result that is not ok carries a reason and no volume.
    VolumeResult estimate(const Surface& baseline, const Surface& current);

    const Parameters& parameters() const;

    // Called on the caller's thread after each stage of measureSurface and estimate (each entry
    // of their timingsMs). The daemon shows the service manager from it that the chain is making
    // progress: a long chain on a slow box is not taken for a hung one, a stage that hangs still is.
    using StageDone = std::function<void()>;
    void onStageDone(StageDone hook);

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace icewatch::volume
