// The estimate's gates (gates.hpp).
#include "core/volume/gates.hpp"

#include <cmath>
#include <sstream>

#include <opencv2/imgproc.hpp>

#include "core/volume/image_quality.hpp"
#include "core/volume/registration.hpp"
#include "core/volume/roi.hpp"
#include "core/volume/row_texture.hpp"
#include "core/volume/silhouette.hpp"

namespace icewatch::volume {

namespace {

// A segmented region reaching more of the frame's edge than this is the view, not an object: a
// blade across the view reaches two sides, about a third of the edge at 2560x720.
constexpr double kMaxSegmentedEdgeShare = 0.6;
// Said of a refusal that a segmented region may explain.
constexpr const char* kNoOutlineHint =
    "; no outline of the object was given (roi.json in a scene, volume.roi_polygon in the configuration) and "
    "the region was found by depth alone: draw the object's outline";
// The most the baseline's plane may be turned out of the view before it is taken for something
// other than the object's surface.
constexpr double kMaxPlaneObliquityDeg = 75.0;

}  // namespace

// The baseline's region: there, and the object rather than the view.
std::optional<std::string> baselineRegionProblem(const Surface& baseline) {
    if (cv::countNonZero(baseline.roi) == 0) return "no region of interest in the baseline";
    if (!baseline.roiSegmented) return std::nullopt;
    // A segmented region that is the view rather than an object: it reaches most of the frame's edge.
    const double edge = frameEdgeShare(baseline.roi);
    if (edge <= kMaxSegmentedEdgeShare) return std::nullopt;
    std::ostringstream problem;
    problem.precision(3);
    problem << "the region found at the object's depth reaches " << 100.0 * edge
            << " % of the frame's edge: it is the view, not the object (a surface it lies on, or a "
               "featureless sky the matcher filled)"
            << kNoOutlineHint;
    return problem.str();
}

// Either capture's images: exposure, contrast, new clipping, and enough valid disparities.
std::optional<std::string> capturesProblem(const Surface& baseline, const Surface& current, const Parameters& p) {
    for (const auto& [surface, which] : {std::pair{&baseline, "baseline"}, std::pair{&current, "current"}}) {
        if (auto problem = imageProblem(surface->quality, p, which)) {
            // A segmented region may hold featureless sky the matcher filled with the object's depth.
            return *problem + (baseline.roiSegmented ? std::string(kNoOutlineHint) : "");
        }
        if (surface == &current) {
            if (auto problem = newSaturationProblem(baseline.quality, current.quality, p)) return problem;
        }
        if (surface->validPercent < p.minValidPercent) {
            std::ostringstream reason;
            reason.precision(3);
            reason << "too few valid disparities in the " << which << " region: " << surface->validPercent
                   << " % < " << p.minValidPercent << " %";
            return reason.str();
        }
    }
    return std::nullopt;
}

// A plane seen edge-on is not the object's surface: the region held more than the object (clouds
// behind an outline drawn as a box 30 px wide of a blade put it 29.9 m away at 89.4°), and the
// outline's rays met it kilometres off, a grid of 4852976 x 768945 nodes, and an error, not a
// reason. The renderer turns an object by at most 45° about each axis (60° about both at once).
std::optional<std::string> edgeOnProblem(const PlaneFrame& plane) {
    const double obliquityDeg = viewObliquityDeg(plane);
    if (obliquityDeg <= kMaxPlaneObliquityDeg) return std::nullopt;
    std::ostringstream reason;
    reason.precision(3);
    reason << "the region's surface is seen edge-on (" << obliquityDeg << "° out of the view, its plane "
           << std::lround(plane.origin[2]) << " mm away, max " << kMaxPlaneObliquityDeg
           << "°): the region holds more than the object, such as a background at other depths inside a "
              "loosely drawn outline; draw the outline on the object's edge";
    return reason.str();
}

// A tone curve or a blur flattens the texture, and with it what a clear glaze does to its look: a
// change of light then cancels the rest, and the texture that kept its look may lie under a layer
// over all of the object. A background the object rests on fixes the motion without it.
std::optional<std::string> faintTextureProblem(const Surface& baseline, const Surface& current,
                                               const MotionEstimate& motion, const Parameters& p) {
    if (motion.backgroundEvidence > 0) return std::nullopt;
    const bool baselineFaint = baseline.quality.contrast < p.minContrastObjectMotion;
    if (!baselineFaint && current.quality.contrast >= p.minContrastObjectMotion) return std::nullopt;
    std::ostringstream reason;
    reason.precision(3);
    reason << "the motion between the captures is not observable: the " << (baselineFaint ? "baseline" : "current")
           << " image's texture is too faint to rest the motion on the object alone (contrast "
           << (baselineFaint ? baseline.quality.contrast : current.quality.contrast) << " < " << p.minContrastObjectMotion
           << ": a tone curve or a blur flattens it, and what a clear glaze over all of the object does to its "
              "look, so that a change of light may cancel the rest), and no background it rests on was found";
    return reason.str();
}

// The thickness map's own refusals: no part of the region on the grid, ice reaching past the ring.
std::optional<std::string> thicknessMapProblem(const ThicknessMap& map, const Parameters& p) {
    if (map.insideNodes == 0) return "the region covers no part of the measured surface";
    return ringEdgeProblem(map, p);
}

// Ice beyond the outline that reaches the ring's outer edge may reach farther, where nothing is
// measured. Icicles hanging from a rendered trailing edge, 60-200 mm long, read -59 to -71 % and
// `ok` outside their uncertainty while the ring cut them at 50 mm: no uncertainty can speak for
// what lies past it. A wider ring is no cure: at 200 mm the same icicles against the sky read -44
// to -58 % (narrow ice against a featureless background is read low, as a bead's is), inside an
// uncertainty up to 3.4 times what was read, so the reason names no setting to change.
std::optional<std::string> ringEdgeProblem(const ThicknessMap& map, const Parameters& p) {
    if (map.beyondAtRingEdgeNodes == 0) return std::nullopt;
    std::ostringstream reason;
    reason << "ice stands out of the outline as far as the ring watched around it reaches (" << map.beyondAtRingEdgeNodes
           << " nodes at its edge, " << p.outlineGrowthMm
           << " mm out): it may reach farther, where nothing is measured (icicles hanging from an edge, a long horn)";
    return reason.str();
}

std::optional<std::string> filledProblem(double filledPercent, const Parameters& p) {
    if (filledPercent <= p.maxFilledPercent) return std::nullopt;
    std::ostringstream reason;
    reason.precision(3);
    reason << filledPercent << " % of the region has no measurement (max " << p.maxFilledPercent << " %)";
    return reason.str();
}

// Ice standing out of the outline on an object turned out of the view: what the camera sees of it
// hides what lies behind it, the background or the object's own surface, and the chain reads that
// hidden space as ice (a bead read as if seen from the front, a horn whose underside the view
// does not reach). Facing the camera, the hidden space is only the ice's own footprint. The ice
// beyond the outline counts when the taper read it from the background it hides, or when it is
// larger than the outline's own uncertainty (k times its term): less is the outline's noise.
std::optional<std::string> outlineObliquityProblem(const ThicknessMap& map, const PlaneFrame& plane,
                                                   const VolumeResult& result, const Parameters& p) {
    const double obliquityDeg = viewObliquityDeg(plane);
    if (obliquityDeg <= p.outlineMaxObliquityDeg) return std::nullopt;
    const double outlineNoise = p.coverageFactor * result.budget.outlineMm3;
    std::ostringstream reason;
    reason.precision(3);
    if (map.taperedNodes > 0) {
        reason << "ice stands out of the outline where only the background it hides shows it, read as a bead seen "
                  "from the front, and the object is turned ";
    } else if (result.beyondOutlineMm3 > outlineNoise) {
        reason << "ice stands out of the outline (" << std::lround(result.beyondOutlineMm3)
               << " mm3, more than the outline's uncertainty of " << std::lround(outlineNoise)
               << " mm3) and hides what lies behind it, which would read as ice: the object is turned ";
    } else {
        return std::nullopt;
    }
    reason << obliquityDeg << "° out of the view (max " << p.outlineMaxObliquityDeg << "°)";
    return reason.str();
}

// Where the texture is weak against the noise the matcher moves the surface by a fraction of a
// pixel that is not there, and over the whole of where the ice may be that is a volume: the
// tracks measure it (MatcherPush), and without them the budget would carry none. A single frame
// of rime patches on a blade on a table through a filmic curve found no texture of the object
// again in its right eye; the matcher read the clean blade 0.2-0.3 px nearer than the baseline,
// and the volume +57.8 % and `ok` against ±36 %.
std::optional<std::string> uncheckedPushProblem(int samples, const Parameters& p) {
    if (samples >= p.minEvidenceSamples) return std::nullopt;
    std::ostringstream reason;
    reason << "the matcher's surface where the ice may be cannot be checked: " << samples
           << " of the object's texture samples there were found again in both eyes (min " << p.minEvidenceSamples
           << "), so how far the matcher moved the surface where the texture is weak against the noise is not known "
              "(a faint texture, noise, a single frame: average more frames)";
    return reason.str();
}

// Ice whose depth the rows could not tell: carried over from around it, not measured (row_texture.hpp).
std::optional<std::string> faintIceProblem(const Surface& baseline, const Surface& current, const PlaneFrame& plane,
                                           const RigidTransform& transform, const cv::Matx33d& k,
                                           std::optional<double> lightRatio, const cv::Mat& unreadLost,
                                           const Parameters& p, VolumeResult& result) {
    const RowTextureOptions rowTexture;
    cv::Mat baselineObject;
    cv::erode(baseline.roi, baselineObject,
              cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * p.edgeMarginPx + 1, 2 * p.edgeMarginPx + 1}));
    const FaintIce faint = faintIce({baseline.leftGrey, current.leftGrey, baseline.leftNoise, current.leftNoise, baselineObject,
                                     [&](cv::Point2d px) { return planePixelInCurrent(px, plane, transform, k).at; },
                                     lightRatio.value_or(1.0), result.thicknessImageMm, unreadLost},
                                    rowTexture);
    result.faintIcePercent = 100.0 * faint.share();
    if (!faint.unmeasured(rowTexture)) return std::nullopt;
    std::ostringstream reason;
    reason.precision(3);
    reason << "the ice's thickness is not measured: " << result.faintIcePercent << " % of the " << faint.icePixels
           << " pixels where ice was read or the object's texture was lost carry less texture along the image rows than "
           << rowTexture.minGreyPerPx
           << " grey levels per pixel, or too little for stereo to read what hid the texture (a blur, a tone curve, "
              "noise or smooth, plain ice), so the matcher carried the depth of the surface around it over it and the "
              "ice may be much thicker than read";
    return reason.str();
}

}  // namespace icewatch::volume
