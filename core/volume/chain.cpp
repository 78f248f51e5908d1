// The volume chain: from two captures (a clean baseline and the current one) to an ice volume
// with an honest error bar, or a refusal with a reason.
//
// The ice is about 0.1 px of disparity at 1280 px per eye, so the chain differences surfaces in a
// common frame rather than trusting absolute depth: both captures are measured with the same
// calibration and matcher, the current one is moved onto the baseline by the motion of the
// texture the ice did not change (tracked in both eyes, without the matcher), and the thickness is
// the difference of the two surfaces along the normal of the baseline's mean plane, where the ice
// may be. Volume is invariant to that choice of direction as long as both surfaces are height
// fields over it, which a nearly fronto-parallel view of a blade or a plate guarantees.
//
// Stages, as the seed paper's section 2.2 with registration and an error budget added, one file
// each:
//   measureSurface: split → rectify → match → tracking images → region (drawn_outline, raised_object)
//                   → image quality
//   estimate:       gate → reproject (Q) → plane frame → texture tracks (texture_tracks) → motion (motion_evidence)
//                   → ice mask (ice_mask) → both clouds on the plane, k-NN filter (plane_clouds)
//                   → grid, thickness (thickness_map) → integrate (trapz | sum) → uncertainty
//                   (uncertainty) → gate
//   Each gate (gates.hpp) refuses, with its reason, as soon as what it judges is known.
#include "core/volume/chain.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <sstream>

#include <opencv2/imgproc.hpp>

#include "core/common/error.hpp"
#include "core/stereo/matcher.hpp"
#include "core/volume/background_light.hpp"
#include "core/volume/beyond_outline.hpp"
#include "core/volume/drawn_outline.hpp"
#include "core/volume/edge_blur.hpp"
#include "core/volume/gates.hpp"
#include "core/volume/height_grid.hpp"
#include "core/volume/ice_mask.hpp"
#include "core/volume/image_motion.hpp"
#include "core/volume/lost_texture.hpp"
#include "core/volume/matcher_push.hpp"
#include "core/volume/motion_evidence.hpp"
#include "core/volume/outline_growth.hpp"
#include "core/volume/plane_clouds.hpp"
#include "core/volume/raised_object.hpp"
#include "core/volume/registration.hpp"
#include "core/volume/roi.hpp"
#include "core/volume/row_texture.hpp"
#include "core/volume/seen_through.hpp"
#include "core/volume/silhouette.hpp"
#include "core/volume/slanted_refinement.hpp"
#include "core/volume/texture_tracks.hpp"
#include "core/volume/thickness_map.hpp"
#include "core/volume/uncertainty.hpp"

namespace icewatch::volume {

namespace {

constexpr double kPi = 3.14159265358979323846;

// Times consecutive stages with the clock the chain was given.
class StageTimer {
public:
    StageTimer(const VolumeChain::Clock& clock, Timings& timings, const VolumeChain::StageDone& done)
        : clock_(clock), timings_(timings), done_(done) {
        start_ = now();
    }
    void lap(const std::string& stage) {
        const auto t = now();
        timings_.emplace_back(stage, std::chrono::duration<double, std::milli>(t - start_).count());
        start_ = t;
        if (done_) done_();
    }

private:
    std::chrono::steady_clock::time_point now() const {
        return clock_ ? clock_() : std::chrono::steady_clock::time_point{};
    }
    const VolumeChain::Clock& clock_;
    Timings& timings_;
    const VolumeChain::StageDone& done_;
    std::chrono::steady_clock::time_point start_;
};

// Grey in floating point: an averaged capture stays as it is, a camera frame is converted.
cv::Mat toFloatGrey(const cv::Mat& image) {
    cv::Mat grey = image;
    if (image.channels() == 3) cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
    cv::Mat out;
    grey.convertTo(out, CV_32F);
    return out;
}

// [X Y Z W]ᵀ = Q·[x y d 1]ᵀ for every valid disparity inside `window` (none lies outside it);
// NaN elsewhere.
cv::Mat reproject(const cv::Mat& disparity, const cv::Mat& q, const cv::Rect& window) {
    const cv::Matx44d Q(q);
    cv::Mat points(disparity.size(), CV_32FC3);
    const cv::Rect inside = window & cv::Rect({0, 0}, disparity.size());
    const cv::Vec3f none = cv::Vec3f::all(std::numeric_limits<float>::quiet_NaN());
    // Each row on its own: the same points whatever the thread count.
    cv::parallel_for_(cv::Range(0, disparity.rows), [&](const cv::Range& rows) {
        for (int y = rows.start; y < rows.end; ++y) {
            const auto* d = disparity.ptr<float>(y);
            auto* out = points.ptr<cv::Vec3f>(y);
            std::fill(out, out + disparity.cols, none);
            if (y < inside.y || y >= inside.y + inside.height) continue;
            for (int x = inside.x; x < inside.x + inside.width; ++x) {
                if (!(d[x] > 0)) continue;
                const cv::Vec4d h = Q * cv::Vec4d(x, y, d[x], 1.0);
                if (std::abs(h[3]) < 1e-12) continue;
                const cv::Vec3f p(static_cast<float>(h[0] / h[3]), static_cast<float>(h[1] / h[3]),
                                  static_cast<float>(h[2] / h[3]));
                if (p[2] > 0) out[x] = p;
            }
        }
    });
    return points;
}

// A window's image placed in a frame-sized one, `outside` elsewhere (the window itself when it is
// the whole frame).
cv::Mat placedInFrame(const cv::Mat& image, const cv::Rect& window, cv::Size frame, float outside) {
    if (window.size() == frame) return image;
    cv::Mat out(frame, image.type(), cv::Scalar::all(outside));
    image.copyTo(out(window));
    return out;
}

VolumeResult refused(VolumeResult result, const std::string& reason) {
    result.ok = false;
    result.reason = reason;
    result.volumeMm3 = result.uncertaintyMm3 = result.meanThicknessMm = result.meanThicknessUncertaintyMm = 0;
    result.maxThicknessMm = 0;
    return result;
}

void checkParameters(const Parameters& p) {
    auto fail = [](const std::string& what) { throw Error(kExitConfig, "volume parameters: " + what); };
    if (p.maxDisparity < 1) fail("max_disparity must be positive");
    if (p.knnK < 2 || p.knnTheta <= 0) fail("knn_k must be >= 2 and knn_theta positive");
    if (p.gridCellMm <= 0) fail("grid_cell_mm must be positive");
    if (p.correlationPx < 1 || p.trackRadiusPx < 1 || p.trackStepPx < 1 || p.trackSearchPx < 1) {
        fail("correlation_px and the track_* sizes must be positive");
    }
    if (p.occlusionSlope < 0 || p.occlusionStepMm < 0) fail("occlusion_slope and occlusion_step_mm must not be negative");
    if (!p.roiPolygon.empty() && (p.roiPolygon.size() % 2 != 0 || p.roiPolygon.size() < 6)) {
        fail("roi_polygon needs x, y pairs for at least 3 points");
    }
}

}  // namespace

struct VolumeChain::Impl {
    calib::StereoCalibration calibration;
    Parameters parameters;
    Clock clock;
    StageDone stageDone;
    calib::Rectifier rectifier;
    stereo::Matcher matcher;
    cv::Mat polygonRoi;  // rectified; empty = segment
    cv::Matx34d projection;
    double focalPx = 0, baselineMm = 0;

    // measureSurface: a baseline (nullptr) in the whole frame, a later capture in its followUp.
    Surface measureFrame(cv::Mat sideBySideFrame, cv::Mat sideBySideNoise, const Surface* baseline);
    Surface measure(StereoPair raw, StereoPair rawNoise, const Surface* baseline);
    MatchRegion followUpRegion(const Surface& baseline) const;
    // What the estimate needs of a baseline alone, from its points.
    std::shared_ptr<const BaselineModel> baselineModel(const Surface& baseline, const cv::Mat& points) const;
    // A baseline with a configured outline: its region and band from a coarse pass (match_region.hpp),
    // over the object the outline holds (drawn_outline.hpp), which it sets in `drawn`.
    MatchRegion coarseRegion(const StereoPair& raw, DrawnOutline& drawn);
    // The object inside the configured outline, as the baseline's left eye `grey` shows it.
    DrawnOutline drawnObject(const cv::Mat& grey) const {
        return objectInDrawnOutline(polygonRoi, grey, parameters.outlineMinTextureGrey, parameters.outlineMinContrastGrey);
    }
    // `disparity` (the matcher's window) measured again on slanted windows over the region's box
    // (slanted_refinement.hpp): the matcher's windows face the camera and its aggregation reaches
    // 35 px, so on a curved or turned surface it leaves a staircase, and beside the ice it pushes
    // the clean surface forward; both move with the ice.
    // Facing the camera a window mostly off the centre's surface is a depth step, where the
    // matcher does better; on an object turned out of the view (the baseline's plane, beyond
    // outline_max_obliquity_deg) it is also the matcher's staircase, which the window is for.
    void refineOnSlantedWindows(const cv::Mat& left, const cv::Mat& right, const MatchRegion& region,
                                const cv::Rect& window, const cv::Mat& roi, bool ofBaseline,
                                const std::optional<PlaneFrame>& baselinePlane, cv::Mat& disparity) const;

    // estimate's stages that need the chain's calibration, matcher or outline.
    struct TrackedTexture {
        std::vector<TextureTrack> tracks;
        TextureTrackOptions options;
        std::optional<double> lightRatio;  // the background's light, current over baseline (background_light.hpp)
    };
    TrackedTexture trackCaptures(const Surface& baseline, const Surface& current, const BaselineModel& model) const;
    std::optional<std::string> outlineGrowthProblem(const Surface& baseline, const Surface& current,
                                                    const BaselineModel& model, const MotionEstimate& motion,
                                                    VolumeResult& result) const;
    int measurementReachPx() const;
    HiddenBackground hiddenBackground(const Surface& baseline, const Surface& current, const BaselineModel& model,
                                      const cv::Mat& ringInCurrent, const cv::Mat& currentRing,
                                      const RigidTransform& transform, std::optional<double> lightRatio) const;
    std::optional<std::string> leftOutBackgroundProblem(const Surface& baseline, const Surface& current,
                                                        const BaselineModel& model, const cv::Mat& objectInCurrent,
                                                        std::optional<double> lightRatio) const;
    void budget(const ThicknessMap& map, const PlaneFrame& plane, const MotionEstimate& motion, const MatcherPush& push,
                const SeenThroughIce& seen, const Surface& current, const BaselineModel& model,
                const cv::Mat& objectInCurrent, VolumeResult& result) const;
};

namespace {

stereo::Parameters matcherParameters(const stereo::Parameters& configured) {
    stereo::Parameters p = configured;
    // Filled holes are invented depth: a volume must be built from measurements only.
    p.sgbmFillHoles = false;
    return p;
}

}  // namespace

VolumeChain::VolumeChain(const calib::StereoCalibration& calibration, const Parameters& parameters, Clock clock,
                         const stereo::Parameters& stereoParameters) {
    checkParameters(parameters);
    calib::StereoCalibration c = calibration;
    calib::validateCalibration(c, "calibration");
    if (c.Q.empty() || c.P1.empty()) calib::deriveRectification(c);
    impl_ = std::make_unique<Impl>(Impl{c, parameters, std::move(clock), {}, calib::Rectifier(c),
                                        stereo::Matcher(parameters.stereoMethod, matcherParameters(stereoParameters)), {},
                                        cv::Matx34d(c.P1), c.rectifiedFocalPx(), c.baselineMm()});
    if (!parameters.roiPolygon.empty()) {
        impl_->polygonRoi = roiMaskFromPolygon(polygonFromFlat(parameters.roiPolygon), c);
    }
    impl_->matcher.setKeepBuffers(false);  // a capture a cycle: Matcher::setKeepBuffers says why
}

VolumeChain::~VolumeChain() = default;
VolumeChain::VolumeChain(VolumeChain&&) noexcept = default;
VolumeChain& VolumeChain::operator=(VolumeChain&&) noexcept = default;

const Parameters& VolumeChain::parameters() const { return impl_->parameters; }

void VolumeChain::onStageDone(StageDone hook) { impl_->stageDone = std::move(hook); }

Surface VolumeChain::measureSurface(cv::Mat sideBySideFrame, cv::Mat sideBySideNoise) {
    return impl_->measureFrame(std::move(sideBySideFrame), std::move(sideBySideNoise), nullptr);
}

Surface VolumeChain::measureSurface(StereoPair raw, StereoPair rawNoise) {
    return impl_->measure(std::move(raw), std::move(rawNoise), nullptr);
}

Surface VolumeChain::measureSurface(cv::Mat sideBySideFrame, const Surface& baseline, cv::Mat sideBySideNoise) {
    return impl_->measureFrame(std::move(sideBySideFrame), std::move(sideBySideNoise), &baseline);
}

Surface VolumeChain::measureSurface(StereoPair raw, const Surface& baseline, StereoPair rawNoise) {
    return impl_->measure(std::move(raw), std::move(rawNoise), &baseline);
}

cv::Mat VolumeChain::points(const Surface& surface) const {
    return reproject(surface.disparity, impl_->calibration.Q, surface.matchedWindow);
}

Surface VolumeChain::Impl::measureFrame(cv::Mat sideBySideFrame, cv::Mat sideBySideNoise, const Surface* baseline) {
    Timings split;
    StageTimer timer(clock, split, stageDone);
    StereoPair raw = sideBySideViews(sideBySideFrame);
    sideBySideFrame.release();  // the views hold the frame now, until the eyes are rectified
    StereoPair rawNoise = sideBySideNoise.empty() ? StereoPair{} : sideBySideViews(sideBySideNoise);
    sideBySideNoise.release();
    timer.lap("split");
    Surface surface = measure(std::move(raw), std::move(rawNoise), baseline);
    surface.timingsMs.insert(surface.timingsMs.begin(), split.front());
    return surface;
}

Surface VolumeChain::Impl::measure(StereoPair raw, StereoPair rawNoise, const Surface* baseline) {
    Surface s;
    StageTimer timer(clock, s.timingsMs, stageDone);
    const cv::Size size = rectifier.imageSize();
    MatchRegion region = baseline && parameters.matchRegion ? baseline->followUp : MatchRegion{};
    // A baseline may be matched anywhere: the whole rectification maps (built again when an
    // earlier baseline left only its region's).
    if (!baseline) rectifier.focus(cv::Rect({0, 0}, size));
    std::optional<DrawnOutline> drawn;  // a baseline's, when a coarse pass found it
    if (!baseline && !polygonRoi.empty() && parameters.matchRegion) {
        drawn.emplace();
        region = coarseRegion(raw, *drawn);
        timer.lap("coarse");
    }
    // The matcher's window: the region's box and, to its left, the band's reach into the right eye.
    const cv::Rect window = region.empty() ? cv::Rect({0, 0}, size) : matcherWindow(region, size);
    cv::Mat left, right;
    {
        if (baseline) rectifier.focus(window);  // kept so after the baseline: nothing to do
        const StereoPair rectified = rectifier.rectify(raw, window);
        raw = {};  // the last reference to the capture, when the caller moved it in
        left = toFloatGrey(rectified.left);
        right = toFloatGrey(rectified.right);
    }
    if (!rawNoise.left.empty()) {
        // Rectified as the eye was: the interpolation shapes the noise's spectrum as it shapes the image's.
        if (rawNoise.left.size() != size || rawNoise.left.type() != CV_32FC1) {
            throw InvalidInput("the capture's noise draw does not have the frame's size and float type");
        }
        s.leftNoise = placedInFrame(rectifier.rectifyLeft(rawNoise.left, window), window, size, 0.0f);
        rawNoise = {};
    }
    timer.lap("rectify");
    // The float average goes to the matcher as it is: its integer stages round it, its sub-pixel
    // refinement reads the fraction the averaging gained.
    s.matched = region;
    s.matched.band = region.empty() ? stereo::DisparityRange{0, parameters.maxDisparity} : region.band;
    s.matchedWindow = window;
    cv::Mat disparity = matcher.compute(left, right, s.matched.band);
    timer.lap("match");
    // A later capture as its baseline was (a baseline once its plane is known, below).
    if (baseline && baseline->model && parameters.slantedWindow) {
        refineOnSlantedWindows(left, right, region, window, baseline->roi, false,
                               std::optional(baseline->model->plane), disparity);
        timer.lap("slanted");
    }
    if (!region.empty()) {
        // Left of the region's box the window only served as the right eye's reach.
        disparity(cv::Rect(0, 0, region.box.x - window.x, window.height)).setTo(stereo::kInvalidDisparity);
    }
    s.disparity = placedInFrame(disparity, window, size, stereo::kInvalidDisparity);
    // After the match, so that none of it is held while the matcher's buffers are.
    s.leftGrey = placedInFrame(left, window, size, 0.0f);
    s.leftGrey.convertTo(s.rectifiedLeft, CV_8U);
    // Prepared here, once per surface: the daemon keeps the baseline's and estimates against it
    // every cycle.
    s.trackLeft = prepareForTracking(left, window.tl());
    s.trackRight = prepareForTracking(right, window.tl());
    timer.lap("prepare");
    // A later capture keeps the baseline's region: segmenting a cropped capture would find a
    // different one, and the estimate measures inside the baseline's anyway.
    // A baseline's points: its segmentation and its model read them; nothing keeps them.
    const cv::Mat points = baseline ? cv::Mat() : reproject(s.disparity, calibration.Q, window);
    if (baseline) {
        s.roi = baseline->roi.clone();
        s.roiSegmented = baseline->roiSegmented;
        s.outlineBackgroundPercent = baseline->outlineBackgroundPercent;
    } else if (!polygonRoi.empty()) {
        // The outline as drawn, less the background a loosely drawn one holds.
        if (!drawn) drawn = drawnObject(s.leftGrey);
        // And less the margin of a textured background it holds, where the object stands above it.
        RaisedObject raised = objectAboveItsBackground(drawn->object, points);
        s.roi = std::move(raised.object);
        s.outlineBackgroundPercent =
            100.0 - (100.0 - drawn->backgroundPercent) * (100.0 - raised.backgroundPercent) / 100.0;
    }
    else {
        s.roi = segmentObject(points, s.leftGrey, parameters.segmentationBandMm, parameters.outlineMinTextureGrey,
                              parameters.outlineMinContrastGrey);
        s.roiSegmented = true;
    }
    s.quality = measureImageQuality(s.rectifiedLeft, s.roi);
    const int inside = cv::countNonZero(s.roi);
    s.validPercent = inside > 0 ? 100.0 * cv::countNonZero((s.disparity >= 0) & s.roi) / inside : 0.0;
    if (baseline) s.shiftFromBaselinePx = globalImageShift(baseline->leftGrey, s.leftGrey, baseline->roi);
    if (baseline && !region.empty() && !imageProblem(s.quality, parameters, "current")) {
        // The object left the matched box when the scene's shift says so, the region no longer
        // looks like the baseline's where it was, and it does where the shift put it. A wrong
        // peak of the shift (bright rime patches that appeared, a repeated texture) does not find
        // the region there, and is the registration's to judge.
        constexpr double kLeftCorrelation = 0.5;
        const cv::Point2d shift = *s.shiftFromBaselinePx;
        if (auto problem = regionProblem(region, size, shift)) {
            const double inPlace = maskedCorrelation(baseline->leftGrey, s.leftGrey, baseline->roi);
            cv::Mat movedBack;
            const cv::Matx23d back(1, 0, -shift.x, 0, 1, -shift.y);
            cv::warpAffine(s.leftGrey, movedBack, back, s.leftGrey.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
            const double whereMoved = maskedCorrelation(baseline->leftGrey, movedBack, baseline->roi);
            if (inPlace < kLeftCorrelation && whereMoved >= kLeftCorrelation) s.regionProblem = *problem;
            // Not found where the shift says either (a shift beyond the correlation's window, or
            // ice that changed the region's look): a guess, said beside the registration's reason
            // should the registration find nothing to rest on.
            else if (inPlace < kLeftCorrelation) s.regionHint = *problem;
        }
    }
    if (!baseline && cv::countNonZero(s.roi) > 0) {
        // Its own plane tells how to weigh the windows: its disparities are measured again on
        // them, and its model built with them.
        if (parameters.slantedWindow) {
            // `disparity` is still the matcher's, over its window, as placed in the frame.
            refineOnSlantedWindows(left, right, region, window, s.roi, true,
                                   baselinePlane(s.roi, points, parameters), disparity);
            disparity.copyTo(s.disparity(window));
            timer.lap("slanted");
        }
        s.model = baselineModel(s, parameters.slantedWindow ? reproject(s.disparity, calibration.Q, window) : points);
        timer.lap("model");
    }
    if (!baseline && parameters.matchRegion) {
        s.followUp = followUpRegion(s);
        // Later captures are rectified in the followUp window alone: only its maps are kept.
        if (!s.followUp.empty()) rectifier.focus(matcherWindow(s.followUp, size));
    }
    timer.lap("region");
    return s;
}

void VolumeChain::Impl::refineOnSlantedWindows(const cv::Mat& left, const cv::Mat& right, const MatchRegion& region,
                                               const cv::Rect& window, const cv::Mat& roi, bool ofBaseline,
                                               const std::optional<PlaneFrame>& baselinePlane,
                                               cv::Mat& disparity) const {
    // Both captures alike over the region's box, where the volume and its ring are read, and there
    // only as far from the region as its surface is read: the box also holds the matcher's reach,
    // and around a blade most of it is sky, where every window fails after its first steps.
    const cv::Rect area = region.empty() ? cv::Rect({0, 0}, window.size()) : region.box - window.tl();
    SlantedRefinement slanted;
    slanted.radius = parameters.slantedWindowRadiusPx;
    slanted.maxSigmaPx = parameters.slantedWindowMaxSigmaPx;
    // Without a plane (too few points: the estimate refuses that baseline) as facing the camera.
    if (baselinePlane && viewObliquityDeg(*baselinePlane) > parameters.outlineMaxObliquityDeg) {
        slanted.minSupportShare = kTurnedOutOfTheViewSupportShare;
    }
    if (parameters.slantedWindowAsBefore) {
        slanted.giveUpFactor = std::numeric_limits<double>::infinity();
        refineSlantedReference(left, right, area, slanted, disparity);
        return;
    }
    cv::Mat where;
    if (!region.empty() && !roi.empty() && cv::countNonZero(roi(window)) > 0) {
        const cv::Mat outside = roi(window) == 0;
        cv::Mat distance;
        cv::distanceTransform(outside, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE);
        where = distance <= region.surfaceMarginPx();
        // A baseline's disparity also starts the stereo track of every tracker sample, on the
        // background too (a table the object lies on): a start off by the matcher's staircase
        // on a turned table may end in another minimum of that track's short search.
        if (ofBaseline) {
            for (int y = 0; y < where.rows; ++y) {
                auto* row = where.ptr<std::uint8_t>(y);
                for (int x = 0; x < where.cols; ++x)
                    if (isSamplePixel(window.x + x, window.y + y, parameters.trackStepPx)) row[x] = 255;
            }
        }
    }
    refineSlanted(left, right, area, slanted, disparity, where);
}

MatchRegion VolumeChain::Impl::coarseRegion(const StereoPair& raw, DrawnOutline& drawn) {
    const int reach = matcherReachPx(parameters.stereoMethod, matcher.parameters());
    const cv::Size size = rectifier.imageSize();
    const cv::Rect window = coarseWindow(polygonRoi, parameters.maxDisparity, reach, kCoarseFactor);
    const StereoPair rectified = rectifier.rectify(raw, window);
    // The band is the object's: a loosely drawn outline's sky holds what lies far behind it (clouds
    // the matcher finds at a few pixels), and a band down to them let the matcher put the blade's
    // faint texture at 8 m.
    const cv::Mat fullLeft = toFloatGrey(rectified.left);
    drawn = drawnObject(placedInFrame(fullLeft, window, size, 0.0f));
    const double scale = 1.0 / kCoarseFactor;
    cv::Mat left, right;
    cv::resize(fullLeft, left, {}, scale, scale, cv::INTER_AREA);
    cv::resize(toFloatGrey(rectified.right), right, {}, scale, scale, cv::INTER_AREA);
    const int coarseMax = std::min(parameters.maxDisparity / kCoarseFactor, left.cols - 1);
    if (coarseMax < stereo::kMinDisparityBand) return {};
    const cv::Mat coarse = matcher.compute(left, right, stereo::DisparityRange{0, coarseMax});
    cv::Mat up;
    cv::resize(coarse, up, window.size(), 0, 0, cv::INTER_NEAREST);
    up *= kCoarseFactor;  // invalid stays negative
    try {
        return baselineRegionFromCoarse(placedInFrame(up, window, size, stereo::kInvalidDisparity), drawn.object,
                                        cv::Matx44d(calibration.Q), focalPx, parameters, reach, kCoarseFactor);
    } catch (const InvalidInput&) {
        return {};  // nothing valid in the outline at the coarse scale: the whole frame, as without one
    }
}

std::shared_ptr<const BaselineModel> VolumeChain::Impl::baselineModel(const Surface& s, const cv::Mat& points) const {
    return std::make_shared<const BaselineModel>(
        buildBaselineModel(s.roi, points, {s.trackLeft, s.trackRight, s.disparity}, s.leftGrey, focalPx, parameters));
}

MatchRegion VolumeChain::Impl::followUpRegion(const Surface& s) const {
    if (cv::countNonZero(s.roi) == 0) return {};
    try {
        return matchRegionFromBaseline(s.disparity, s.roi, cv::Matx44d(calibration.Q), focalPx, parameters,
                                       matcherReachPx(parameters.stereoMethod, matcher.parameters()));
    } catch (const InvalidInput&) {
        return {};  // no valid disparity in the region: the estimate refuses this baseline anyway
    }
}

namespace {

// --- the stages estimate() calls, in its order (its gates are in gates.hpp) ---

// How the motion is judged from the tracks (motion_evidence.hpp).
MotionEvidenceOptions motionEvidenceOptions(const Parameters& p, std::optional<double> lightRatio) {
    MotionEvidenceOptions evidence;
    evidence.minPairs = p.minEvidenceSamples;
    evidence.minSupportSpanPercent = p.minSupportSpanPercent;
    evidence.backgroundBandMm = p.backgroundBandMm;
    evidence.maxObjectAloneLightSpread = p.maxObjectAloneLightSpreadPercent / 100.0;
    evidence.lightRatio = lightRatio;
    // Neighbouring tracks' windows overlap: their errors are not independent.
    const double overlap = (2.0 * p.trackRadiusPx + 1) / p.trackStepPx;
    evidence.fit.correlationFactor = std::max(1.0, overlap * overlap);
    return evidence;
}

// What the tracks and the motion say, for the result.
void recordEvidence(const std::vector<TextureTrack>& tracks, const MotionEstimate& motion, VolumeResult& result) {
    result.objectLightShift = motion.objectLightShift;
    result.objectLightSpread = motion.objectLightSpread;
    for (const TextureTrack& t : tracks) {
        if (t.state == TextureTrack::State::Unchanged) ++result.unchangedSamples;
        if (t.state == TextureTrack::State::Changed && t.onObject) ++result.changedSamples;
    }
    result.textureInliers = motion.objectEvidence;
    result.backgroundInliers = motion.backgroundEvidence;
    result.registrationSource = motion.source;
    result.supportSpanPercent = motion.supportSpanPercent;
}

// Why the motion was not found, with what the light says and, where the object's texture was
// hardly found at all, what the region's search says.
std::string unregisteredReason(const MotionEstimate& motion, const std::vector<TextureTrack>& tracks,
                               std::optional<double> lightRatio, const TextureTrackOptions& trackOptions,
                               const Surface& current, const Parameters& p) {
    const std::string light =
        motion.objectLightShifted ? "" : objectLightNote(tracks, lightRatio, trackOptions.maxBrightnessChange);
    const std::string reason = light.empty() ? motion.reason : motion.reason + "; " + light;
    // The scene's shift said the object left the matched box, and the region was not found
    // there either: a guess, and one its texture found again where it was contradicts. A
    // repeated texture (ridges of ice) gave a moved blade's shift a peak 241 px away, and the
    // refusal told the operator to take a new baseline when the light on the blade was what
    // failed; a blank blade under white ice, found neither in place nor 163 px away, was told
    // it had moved out when nothing said how it moved.
    const auto foundOnObject = std::count_if(tracks.begin(), tracks.end(), [](const TextureTrack& t) {
        return t.state != TextureTrack::State::Untracked && t.onObject;  // its look kept or not
    });
    if (!current.regionHint.empty() && foundOnObject < p.minEvidenceSamples) return reason + "; or " + current.regionHint;
    return reason;
}

// The motion, for the result: how far it moved the object's plane, and how well it fitted.
void recordRegistration(const MotionEstimate& motion, const PlaneFrame& plane, VolumeResult& result) {
    const RigidTransform& transform = motion.transform;
    result.registrationMm = cv::norm(transform.apply(plane.origin) - plane.origin);
    result.registrationDeg = std::acos(std::clamp((cv::trace(transform.rotation) - 1.0) / 2.0, -1.0, 1.0)) * 180.0 / kPi;
    result.registrationRmsMm = std::sqrt(motion.chi2PerDof);
    result.registration = transform;
}

// The matcher against the tracks on the clean texture beside the ice, and on every texture found
// again (under a clear layer too, where no clean texture is left): the larger of the two.
// `checkedSamples`: how many samples the second rests on (the first's are among them).
MatcherPush strongerPush(const std::vector<TextureTrack>& tracks, const MotionEstimate& motion,
                         const Surface& baseline, const Surface& current, const cv::Mat& possibleIce,
                         double correlationFactor, int& checkedSamples) {
    std::vector<std::uint8_t> found(tracks.size(), 0);
    for (std::size_t i = 0; i < tracks.size(); ++i) found[i] = tracks[i].state != TextureTrack::State::Untracked;
    MatcherPush onClean = matcherPush(tracks, motion.clean, baseline.disparity, current.disparity, possibleIce, correlationFactor);
    MatcherPush onFound = matcherPush(tracks, found, baseline.disparity, current.disparity, possibleIce, correlationFactor);
    checkedSamples = onFound.samples;
    return std::abs(onFound.meanPx) > std::abs(onClean.meanPx) ? onFound : onClean;
}

// Integrates the thickness; ice the texture was seen through, the matcher read as low as
// refraction shows it (seen_through.hpp), and is counted at its share.
IceSummary integrateIce(const ThicknessMap& map, const SeenThroughIce& seen, const Parameters& p, VolumeResult& result) {
    IceSummary ice = summarise(map, p.integration);
    result.volumeMm3 = ice.volumeMm3 + seenThroughShareMm3(seen);
    result.seenThroughMm3 = seen.readMm3;
    result.glimpsedThroughMm3 = seen.glimpsedReadMm3;
    result.areaMm2 = ice.areaMm2;
    result.iceAreaMm2 = ice.iceAreaMm2;
    result.beyondOutlineMm3 = ice.beyondOutlineMm3;
    result.beyondOutlineAreaMm2 = ice.beyondOutlineAreaMm2;
    result.meanThicknessMm = ice.areaMm2 > 0 ? result.volumeMm3 / ice.areaMm2 : 0.0;
    result.maxThicknessMm = ice.maxThicknessMm;
    return ice;
}

// The current surface in the baseline's frame, each point with the thickness of its grid node,
// for the picture of the cloud.
void recordCloud(const PlaneClouds& clouds, const ThicknessMap& map, const PlaneFrame& plane, VolumeResult& result) {
    const GridSpec& grid = map.grid;
    for (int y = 0; y < clouds.current.rows; ++y)
        for (int x = 0; x < clouds.current.cols; ++x) {
            const cv::Vec3d local = clouds.current.at<cv::Vec3d>(y, x);
            if (std::isnan(local[2])) continue;
            const int i = static_cast<int>(std::lround((local[0] - grid.u0) / grid.du));
            const int j = static_cast<int>(std::lround((local[1] - grid.v0) / grid.dv));
            const bool onGrid = i >= 0 && j >= 0 && i < grid.nu && j < grid.nv;
            result.cloudMm.push_back(cv::Vec3f(plane.toCamera(local[0], local[1], local[2])));
            result.cloudThicknessMm.push_back(onGrid ? static_cast<float>(map.thickness.at<double>(j, i)) : 0.0f);
        }
}

}  // namespace

// The texture the ice did not change, tracked from the baseline to the current capture in both
// eyes (texture_tracks.hpp), and the light on the background between them.
VolumeChain::Impl::TrackedTexture VolumeChain::Impl::trackCaptures(const Surface& baseline, const Surface& current,
                                                                   const BaselineModel& model) const {
    const RectifiedCapture before{baseline.trackLeft, baseline.trackRight, baseline.disparity};
    const RectifiedCapture after{current.trackLeft, current.trackRight, current.disparity};
    TrackedTexture tracked;
    tracked.options = textureTrackOptions(parameters);
    // The trackers start from the object's image motion, found around the scene's global shift; a
    // phase correlation can lock onto the wrong peak (bright ice that appeared, a repeated
    // texture), so a shift larger than any motion the registration accepts is not believed and the
    // search starts where the object was.
    cv::Point2d shift = current.shiftFromBaselinePx ? *current.shiftFromBaselinePx
                                                    : globalImageShift(baseline.leftGrey, current.leftGrey, baseline.roi);
    if (cv::norm(shift) > parameters.maxRegistrationMm * focalPx / model.plane.origin[2]) shift = {0, 0};
    const cv::Matx23d imageMotion =
        objectImageMotion(baseline.leftGrey, current.leftGrey, baseline.roi, shift,
                          confirmedShift(baseline.leftGrey, current.leftGrey, baseline.roi, shift));
    tracked.lightRatio = backgroundLightRatio(baseline.leftGrey, current.leftGrey, baseline.roi,
                                              baseline.matchedWindow, current.matchedWindow);
    tracked.tracks = trackTexture(model.samples, before, after, cv::Matx44d(calibration.Q), imageMotion,
                                  tracked.lightRatio, tracked.options);
    return tracked;
}

// A layer over the whole object wraps its edges as well, and the texture that kept its look under
// it (a clear glaze brightening it as much as the sun dimmed) moved with the layer's surface: the
// outline grown against the sky on both long sides says so where the texture cannot.
std::optional<std::string> VolumeChain::Impl::outlineGrowthProblem(const Surface& baseline, const Surface& current,
                                                                   const BaselineModel& model,
                                                                   const MotionEstimate& motion,
                                                                   VolumeResult& result) const {
    if (model.featureless.empty()) return std::nullopt;
    OutlineGrowthOptions growthOptions;
    growthOptions.blurPx = model.blurPx.value_or(0.0);
    const OutlineGrowth growth = outlineGrowth(baseline.leftGrey, current.leftGrey, baseline.roi, model.featureless,
                                               model.plane, motion.transform, projection.get_minor<3, 3>(0, 0),
                                               baseline.matchedWindow & current.matchedWindow, growthOptions);
    result.outlineGrowthMm = growth.medianMm;
    result.outlineGrowthStations = growth.stations;
    if (!growth.bothSidesChanged || motion.backgroundEvidence > 0) return std::nullopt;
    std::ostringstream reason;
    reason.precision(3);
    reason << "the motion between the captures is not observable: the outline changed against the sky on both "
              "long sides beyond the motion the object's texture gives (the width it covers by "
           << growth.medianMm[0] << " and " << growth.medianMm[1] << " mm at the median of " << growth.stations[0]
           << " and " << growth.stations[1]
           << " places): ice over its edges too, or a motion that is not the object's, so the texture that kept "
              "its look may lie under a layer over all of the object, and no background it rests on was found";
    return reason.str();
}

// How far around the ice its measurement reaches: the slanted window's, or without it the
// matcher's aggregation, which spreads the ice's disparity 35 px around it.
int VolumeChain::Impl::measurementReachPx() const {
    const Parameters& p = parameters;
    return p.slantedWindow ? p.iceMaskGrowPx : std::max(p.iceMaskGrowPx, matcherReachPx(p.stereoMethod, matcher.parameters()));
}

// What the current capture hides of the background in the ring around its outline (`ringInCurrent`,
// off the outline's mixed edge), where the baseline saw background too (the object's edge, moved,
// is not ice).
HiddenBackground VolumeChain::Impl::hiddenBackground(const Surface& baseline, const Surface& current,
                                                     const BaselineModel& model, const cv::Mat& ringInCurrent,
                                                     const cv::Mat& currentRing, const RigidTransform& transform,
                                                     std::optional<double> lightRatio) const {
    HiddenBackground hidden;
    if (!lightRatio || model.ringPx == 0) return hidden;
    cv::Mat where = ringInCurrent.clone();
    where.setTo(0, model.objectGrown);
    hidden.pixels = backgroundHidden(baseline.leftGrey, current.leftGrey, where, *lightRatio, parameters.outlineMinContrastGrey);
    hidden.toBaseline = transform;
    // Beads above a blade on a table, read by the matcher as the table behind them, read -44 to
    // -71 % and `ok` outside their bars before the table they hide told them.
    hidden.unread = unreadBackground(hidden.pixels, model.ringMeasurable, currentRing, model.featureless);
    return hidden;
}

// Left out as background where the object's texture was as featureless as the sky, the surface is
// measured nowhere; ice that appears there is outside everything the chain reads.
std::optional<std::string> VolumeChain::Impl::leftOutBackgroundProblem(const Surface& baseline, const Surface& current,
                                                                       const BaselineModel& model,
                                                                       const cv::Mat& objectInCurrent,
                                                                       std::optional<double> lightRatio) const {
    if (!lightRatio || polygonRoi.empty() || baseline.outlineBackgroundPercent <= 0) return std::nullopt;
    cv::Mat leftOut = leftOutBackground(polygonRoi, baseline.roi, objectInCurrent, model.ringPx);
    cv::Mat inBoth = cv::Mat::zeros(leftOut.size(), CV_8U);
    inBoth(baseline.matchedWindow & current.matchedWindow & cv::Rect({}, leftOut.size())).setTo(255);
    leftOut &= inBoth;
    const cv::Mat appeared =
        backgroundHidden(baseline.leftGrey, current.leftGrey, leftOut, *lightRatio, parameters.outlineMinContrastGrey);
    const int appearedPx = cv::countNonZero(appeared);
    if (appearedPx < parameters.trackStepPx * parameters.trackStepPx) return std::nullopt;
    std::ostringstream reason;
    reason.precision(3);
    reason << "something appeared in what was left out of the drawn outline as background (" << appearedPx
           << " pixels beyond the " << model.ringPx << " px ring around the region; " << baseline.outlineBackgroundPercent
           << " % of the outline was left out): ice on a part of the object whose texture is too faint to "
              "tell from its background, which the region does not hold; draw the outline on the object's "
              "edge, or give it texture";
    return reason.str();
}

// The volume's error budget (uncertainty.hpp), with what the captures' blur and the view's angle
// add to it.
void VolumeChain::Impl::budget(const ThicknessMap& map, const PlaneFrame& plane, const MotionEstimate& motion,
                               const MatcherPush& push, const SeenThroughIce& seen, const Surface& current,
                               const BaselineModel& model, const cv::Mat& objectInCurrent,
                               VolumeResult& result) const {
    const Parameters& p = parameters;
    // Blurred captures spread every step of the ice: the more blurred of the two, as its outline
    // or the edge around it shows.
    const std::optional<double> currentBlur = objectBlurPx(current.leftGrey, objectInCurrent, current.matchedWindow);
    result.blurPx = std::max(model.blurPx.value_or(0.0), currentBlur.value_or(0.0));
    // Seen at an angle the ice's edges occlude the surface behind them, as far as the surface's
    // measurement reaches (the same reach the ice mask grew by).
    const double fatteningPx = viewObliquityDeg(plane) > p.outlineMaxObliquityDeg
                                   ? (p.slantedWindow ? p.slantedWindowRadiusPx : measurementReachPx())
                                   : 0.0;
    result.budget = volumeUncertainty(map, plane, motion, push,
                                      {focalPx, baselineMm, plane.origin[2], fatteningPx, blurBeyondPixelsPx(result.blurPx)},
                                      p, result.volumeMm3, seen);
    result.uncertaintyMm3 = expandedUncertainty(result.budget, p.coverageFactor);
    result.meanThicknessUncertaintyMm = result.areaMm2 > 0 ? result.uncertaintyMm3 / result.areaMm2 : 0.0;
}

VolumeResult VolumeChain::estimate(const Surface& baseline, const Surface& current) {
    const Parameters& p = impl_->parameters;
    VolumeResult result;
    StageTimer timer(impl_->clock, result.timingsMs, impl_->stageDone);
    if (baseline.disparity.empty() || baseline.disparity.size() != current.disparity.size() ||
        baseline.leftGrey.size() != current.leftGrey.size()) {
        throw InvalidInput("volume: baseline and current surfaces must come from the same calibration");
    }
    result.validPercent = current.validPercent;
    if (!current.regionProblem.empty()) return refused(result, current.regionProblem);

    // --- gate on the images ---
    if (auto problem = baselineRegionProblem(baseline)) return refused(result, *problem);
    result.outlineBackgroundPercent = baseline.outlineBackgroundPercent;
    result.baselineContrast = baseline.quality.contrast;
    result.currentContrast = current.quality.contrast;
    if (auto problem = capturesProblem(baseline, current, p)) return refused(result, *problem);

    // --- what the estimate needs of the baseline alone: kept with a baseline's surface ---
    const std::shared_ptr<const BaselineModel> model =
        baseline.model ? baseline.model : impl_->baselineModel(baseline, points(baseline));
    if (model->measuredPoints < p.minPoints) {
        return refused(result, "too few baseline points in the region: " + std::to_string(model->measuredPoints));
    }
    const PlaneFrame& plane = model->plane;
    timer.lap("plane");
    if (auto problem = edgeOnProblem(plane)) return refused(result, *problem);

    // --- how the object moved: from the texture the ice did not change, in both eyes ---
    const Impl::TrackedTexture tracked = impl_->trackCaptures(baseline, current, *model);
    const std::vector<TextureTrack>& tracks = tracked.tracks;
    timer.lap("track");
    const MotionEvidenceOptions evidence = motionEvidenceOptions(p, tracked.lightRatio);
    const MotionEstimate motion = estimateMotion(tracks, plane, evidence);
    recordEvidence(tracks, motion, result);
    timer.lap("register");
    if (!motion.ok) {
        return refused(result, unregisteredReason(motion, tracks, tracked.lightRatio, tracked.options, current, p));
    }
    const RigidTransform& transform = motion.transform;
    recordRegistration(motion, plane, result);
    if (result.registrationMm > p.maxRegistrationMm) {
        return refused(result, "registration moved the object by " + std::to_string(result.registrationMm) +
                                   " mm, more than max_registration_mm");
    }
    if (auto problem = faintTextureProblem(baseline, current, motion, p)) return refused(result, *problem);
    if (auto problem = impl_->outlineGrowthProblem(baseline, current, *model, motion, result)) {
        return refused(result, *problem);
    }

    // --- where the ice may be, and how far the matcher pushed the clean surface beside it ---
    const cv::Mat possibleIce = iceMask(baseline.roi, tracks, motion.clean, p.trackStepPx, impl_->measurementReachPx());
    result.iceMaskPercent = 100.0 * cv::countNonZero(possibleIce) / std::max(1, cv::countNonZero(baseline.roi));
    int pushSamples = 0;
    const MatcherPush push =
        strongerPush(tracks, motion, baseline, current, possibleIce, evidence.fit.correlationFactor, pushSamples);
    result.matcherPushPx = push.meanPx;
    result.matcherPushSigmaPx = push.sigmaPx;

    // --- both clouds on the baseline's plane, strays out ---
    // Inside the outline off its mixed edge, and the ring around it where ice may stand out of it.
    const cv::Mat currentOutline = outlineInCurrent(baseline.roi, plane, transform, impl_->projection, p.edgeMarginPx);
    const cv::Mat objectInCurrent = outlineInCurrent(baseline.roi, plane, transform, impl_->projection, 0);
    const RectifiedCapture after{current.trackLeft, current.trackRight, current.disparity};
    const cv::Mat ringInCurrent = outlineRing(objectInCurrent, model->ringPx, p.edgeMarginPx);
    const cv::Mat currentRing = measurableRing(after, ringInCurrent, p);
    const HiddenBackground hidden =
        impl_->hiddenBackground(baseline, current, *model, ringInCurrent, currentRing, transform, tracked.lightRatio);
    if (auto problem = impl_->leftOutBackgroundProblem(baseline, current, *model, objectInCurrent, tracked.lightRatio)) {
        return refused(result, *problem);
    }
    const PlaneClouds clouds =
        planeClouds(model->cloud, model->ring, points(current), currentOutline, currentRing, plane, transform, p);
    result.pointsUsed = clouds.currentPoints;
    timer.lap("filter");
    if (result.pointsUsed < p.minPoints) {
        return refused(result, "too few current points in the region: " + std::to_string(result.pointsUsed));
    }

    // --- thickness on the plane's grid, where the ice may be ---
    const cv::Matx33d k = impl_->projection.get_minor<3, 3>(0, 0);
    const OutlineGrid region = outlineGrid(baseline.roi | model->ringMask, plane, k, p.gridCellMm);
    if (!region.grid) {
        // A plane under kMaxPlaneObliquityDeg still grazes the rays at the frame's edge.
        return refused(result, "the region's outline does not lie on the object's plane (" + region.problem +
                                   "): the region holds more than the object; draw the outline on the object's edge");
    }
    const ThicknessMap map =
        thicknessMap(*region.grid, clouds, baseline.roi, model->ringMask, possibleIce, plane, k, p, hidden,
                     seenThroughPixels(baseline.roi, tracks, p.trackStepPx, motion.objectLightShifted));
    if (auto problem = thicknessMapProblem(map, p)) return refused(result, *problem);
    result.filledPercent = 100.0 * map.filledNodes / std::max(1, map.iceNodes);
    timer.lap("grid");
    if (auto problem = filledProblem(result.filledPercent, p)) return refused(result, *problem);

    // The push (above) measured, or the matcher's surface where the ice may be is not known.
    if (auto problem = uncheckedPushProblem(pushSamples, p)) return refused(result, *problem);

    // --- integrate ---
    const SeenThroughIce seen = seenThroughIce(map);
    const IceSummary ice = integrateIce(map, seen, p, result);
    timer.lap("integrate");

    // --- uncertainty ---
    impl_->budget(map, plane, motion, push, seen, current, *model, objectInCurrent, result);
    timer.lap("uncertainty");
    if (auto problem = outlineObliquityProblem(map, plane, result, p)) return refused(result, *problem);

    // --- for people (core/pictures draws it) ---
    result.thicknessImageMm =
        thicknessInImage(ice.smoothedMm, map.grid, plane, transform, k.inv(), currentOutline | currentRing);
    recordCloud(clouds, map, plane, result);

    // --- the gate on what the rows could not tell, and what hid the texture where stereo cannot read it ---
    // Without a draw of its noise a capture's rows cannot tell texture from noise (row_texture.hpp).
    const cv::Mat unreadLost =
        current.leftNoise.empty()
            ? unreadLostTexture(tracks, after, [&](cv::Point2d px) { return planePixelInCurrent(px, plane, transform, k).at; },
                                tracked.options)
            : cv::Mat();
    if (auto problem = faintIceProblem(baseline, current, plane, transform, k, tracked.lightRatio, unreadLost, p, result)) {
        return refused(result, *problem);
    }
    result.ok = true;
    timer.lap("gate");
    return result;
}

}  // namespace icewatch::volume
