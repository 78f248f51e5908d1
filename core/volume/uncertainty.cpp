// The volume's error budget (uncertainty.hpp).
#include "core/volume/uncertainty.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "core/volume/beyond_outline.hpp"
#include "core/volume/rigid_motion.hpp"
#include "core/volume/robust_statistics.hpp"

namespace icewatch::volume {

namespace {

// d(volume) / d(motion) for a left perturbation (rotation vector, translation) of the current
// surface: each ice node's normal displacement, times its area.
cv::Vec6d volumeGradient(const ThicknessMap& map, const PlaneFrame& plane) {
    const GridSpec& grid = map.grid;
    cv::Vec6d gradient(0, 0, 0, 0, 0, 0);
    for (int j = 0; j < grid.nv; ++j)
        for (int i = 0; i < grid.nu; ++i) {
            if (!map.onIce.at<std::uint8_t>(j, i)) continue;
            const double h = map.baselineHeight.at<double>(j, i);
            const cv::Vec3d node = plane.toCamera(grid.u0 + i * grid.du, grid.v0 + j * grid.dv, std::isnan(h) ? 0.0 : h);
            const cv::Vec3d c = node.cross(plane.normal);
            gradient += cv::Vec6d(c[0], c[1], c[2], plane.normal[0], plane.normal[1], plane.normal[2]) * grid.areaPerNodeMm2();
        }
    return gradient;
}

double registrationSigma(const cv::Vec6d& gradient, const MotionEstimate& motion) {
    double jackknifeVariance = 0;
    for (const cv::Vec6d& delta : motion.jackknife) {
        const double dv = gradient.dot(delta);
        jackknifeVariance += dv * dv;
    }
    if (!motion.jackknife.empty()) {
        const double groups = static_cast<double>(motion.jackknife.size());
        jackknifeVariance *= (groups - 1.0) / groups;
    }
    return std::max(propagate(gradient, motion.covariance), std::sqrt(jackknifeVariance));
}

// ∫ max(0, |∇t| - median |∇t|) over the region, on the thickness averaged over 7 × 7 nodes, the
// thickness taken no higher than capMm (a step counts up to that height).
double edgeIntegral(const ThicknessMap& map, double capMm = std::numeric_limits<double>::infinity()) {
    const GridSpec& grid = map.grid;
    cv::Mat capped = map.thickness.clone();
    capped.forEach<double>([capMm](double& t, const int*) { t = t > capMm ? capMm : t; });  // NaN stays NaN
    const cv::Mat smoothed = finiteBoxMean(capped, 3);
    std::vector<double> gradients;
    for (int j = 1; j + 1 < grid.nv; ++j)
        for (int i = 1; i + 1 < grid.nu; ++i) {
            if (!map.inside.at<std::uint8_t>(j, i)) continue;
            const double gx = (smoothed.at<double>(j, i + 1) - smoothed.at<double>(j, i - 1)) / (2 * grid.du);
            const double gy = (smoothed.at<double>(j + 1, i) - smoothed.at<double>(j - 1, i)) / (2 * grid.dv);
            const double g = std::hypot(gx, gy);
            if (!std::isnan(g)) gradients.push_back(g);
        }
    if (gradients.empty()) return 0.0;
    const double floor = median(gradients);
    double integral = 0;
    for (double g : gradients) integral += std::max(0.0, g - floor) * grid.areaPerNodeMm2();
    return integral;
}

// ∫ t dl along the outline: the thickness of the region's nodes next to a node that is neither in
// the region nor ice beyond it, times the node spacing across that boundary.
double outlineIceIntegral(const ThicknessMap& map) {
    const GridSpec& grid = map.grid;
    double integral = 0;
    auto open = [&](int j, int i) {
        return j < 0 || i < 0 || j >= grid.nv || i >= grid.nu ||
               !(map.inside.at<std::uint8_t>(j, i) || (!map.beyond.empty() && map.beyond.at<std::uint8_t>(j, i)));
    };
    for (int j = 0; j < grid.nv; ++j)
        for (int i = 0; i < grid.nu; ++i) {
            if (!map.inside.at<std::uint8_t>(j, i)) continue;
            const double t = map.thickness.at<double>(j, i);
            if (!(t > 0)) continue;
            if (open(j, i - 1) || open(j, i + 1)) integral += t * grid.dv;
            if (open(j - 1, i) || open(j + 1, i)) integral += t * grid.du;
        }
    return integral;
}

// The most that the tapered parts (ThicknessMap::tapered) may hold, mm³: each part a block as high
// as the ice on the outline (1.5 times its taper), or as deep as it is wide, whichever is more.
double deepestTaperedMm3(const ThicknessMap& map) {
    if (map.taperedNodes == 0) return 0.0;
    const GridSpec& grid = map.grid;
    const cv::Mat across = widthAcrossMm(map.tapered, std::max(grid.du, grid.dv));
    cv::Mat labels;
    const int parts = cv::connectedComponents(map.tapered, labels, 8, CV_32S);
    std::vector<double> taper(parts, 0.0), width(parts, 0.0);
    for (int j = 0; j < grid.nv; ++j)
        for (int i = 0; i < grid.nu; ++i) {
            const int part = labels.at<int>(j, i);
            if (part == 0) continue;
            taper[part] += map.thickness.at<double>(j, i);
            width[part] += across.at<double>(j, i);
        }
    double deepest = 0;
    for (int part = 1; part < parts; ++part) deepest += std::max(1.5 * taper[part], width[part]);
    return deepest * grid.areaPerNodeMm2();
}

}  // namespace

UncertaintyBudget volumeUncertainty(const ThicknessMap& map, const PlaneFrame& plane, const MotionEstimate& motion,
                                    const MatcherPush& push, const ViewGeometry& view, const Parameters& p,
                                    double volumeMm3, const SeenThroughIce& seenThrough) {
    const double iceAreaMm2 = map.iceNodes * map.grid.areaPerNodeMm2();
    const double depthPerPxMm = view.depthMm * view.depthMm / (view.focalPx * view.baselineMm);  // ΔZ of 1 px
    const double pixelMm = view.depthMm / view.focalPx;
    const double pointSigmaMm = std::sqrt(2.0) * depthPerPxMm * p.disparityNoisePx;
    const double icePixels = iceAreaMm2 / (pixelMm * pixelMm);
    const double independent = std::max(1.0, icePixels / double(p.correlationPx * p.correlationPx));
    UncertaintyBudget b;
    b.noiseMm3 = iceAreaMm2 * pointSigmaMm / std::sqrt(independent);
    b.registrationMm3 = registrationSigma(volumeGradient(map, plane), motion);
    b.trackingMm3 = p.trackBiasPx * depthPerPxMm * iceAreaMm2;
    // The mean and what is not known of it (its standard error): on weak, noisy texture the tracks
    // scatter too much to see a matcher 0.05 px behind the glaze (noise 4.5 grey levels: -23 %
    // read as ok against +-36 000 mm3 with the mean alone). The single samples' scatter itself is
    // the noise the other terms carry for the whole area.
    b.pushMm3 = std::hypot(push.meanPx, push.sigmaPx) * depthPerPxMm * iceAreaMm2;
    b.biasMm3 = p.subpixelBiasPx * depthPerPxMm * iceAreaMm2;
    const double edges = edgeIntegral(map);
    b.edgeMm3 = p.edgeUncertaintyPx * pixelMm * edges;
    // Rime patches on a table seen 45° from below (rendered, 16 frames): within 3 px of a patch the
    // current capture read the surface 0.25 px too near, within 6 px 0.1 px, and the volume +28 %.
    // Where the matcher's values give no side of the step (they fattened too) a window cannot
    // keep to one side: weighting its pixels by their brightness as well did not (+27 %).
    // The whole reach is the 1 σ, not a uniform spread's reach/√3: the error is all on one side
    // and beside a step the windows often give up, their support short of their share, leaving
    // the matcher's value with its own, wider reach. Rime patches on a table seen at 45°, seeds
    // not in any table, read +13 to +52 %, every one high, at up to 0.85 of the uncertainty with
    // reach/√3 (seed 5: +52 %, of which the fattening term, then 51 503 mm³, carried the most).
    // Facing the camera (and at an angle too, where its own reach is shorter) the steps that the
    // windows' weights cannot see, up to the separable height (Parameters::facingFatteningPx).
    const double separableMm = p.fatteningSeparableStepPx * depthPerPxMm;
    // A blurred step reaches further: shed sheets on a table, their steps sharp, read +12 % within
    // +-73 183 mm3; blurred by 1.5 px +45 % within +-88 729, by 2 px +53 % outside +-101 151.
    const double blurReachPx = p.blurFatteningPerPx * view.blurPx;
    b.fatteningMm3 = std::max((view.fatteningPx + blurReachPx) * pixelMm * edges,
                              (p.facingFatteningPx + blurReachPx) * pixelMm * edgeIntegral(map, separableMm));
    b.scaleMm3 = 0.01 * p.scaleUncertaintyPercent * std::abs(volumeMm3);
    // Beyond the outline no surface was seen under the ice: where it meets the object is taken
    // from the outline's nearest measurement, off the edge by the edge margin. One error for all.
    const double footingMm3 = p.outlineFootingMm * map.beyondNodes * map.grid.areaPerNodeMm2();
    // And next to the outline the ring is blind (its edge margin, and the reach of a patch from the
    // featureless sky): ice on the outline may stand out of it that far unseen, as high as it is
    // on the outline (a bead of a few pixels; anything from none to all of it, 1/sqrt(3)).
    const double blindMm = (p.edgeMarginPx + kRingPatchRadiusPx) * pixelMm;
    const double unseenMm3 = blindMm * outlineIceIntegral(map) / std::sqrt(3.0);
    // Where ice seen only by the background it hides stands (it is tapered from the outline's
    // height, below), the outline's surface was read against it now and against the
    // featureless sky, filled with an arbitrary depth, in the baseline: the matcher's pull differs
    // between the captures there, and the ice tapered from the outline's height inherits it. On
    // rendered beads against the sky the whole read 4-67 % low (hand-run against the truth: a
    // 257 391 mm3 bead at JPEG quality 75 lost 23 % inside the outline, four fifths of it within
    // 12 px of it, and in front of it read 70 091 mm3 where quality 90 read 94 631). As much again
    // as was read, or none of it: 1/sqrt(3). What hid the background where the outline read too
    // thin for ice is not counted (a cloud behind a clean edge hides it too); it may be ice as high
    // on the outline as the least that counts, or more as the same pull goes.
    double taperedMm3 = 0, fringeMm3 = 0, thinMm3 = 0;
    for (int j = 0; j < map.grid.nv; ++j)
        for (int i = 0; i < map.grid.nu; ++i) {
            if (map.taperedNodes > 0 && map.tapered.at<std::uint8_t>(j, i)) taperedMm3 += map.thickness.at<double>(j, i);
            if (!map.fringe.empty() && map.fringe.at<std::uint8_t>(j, i)) {
                fringeMm3 += std::max(0.0, map.thickness.at<double>(j, i));
            }
            if (!map.thinBeyondMm.empty() && !std::isnan(map.thinBeyondMm.at<double>(j, i))) {
                thinMm3 += map.thinBeyondMm.at<double>(j, i);
            }
        }
    taperedMm3 *= map.grid.areaPerNodeMm2();
    fringeMm3 *= map.grid.areaPerNodeMm2();
    thinMm3 *= map.grid.areaPerNodeMm2();
    // Ice seen only by the background it hides is tapered from the outline's height to nothing as a
    // rounded bead (2/3 of height times width); a wedge (1/2) bounds it from below, uniformly up to
    // a block as high as the outline's ice (1) or, where a part stands out wider than that, as deep
    // as it is wide (widthAcrossMm: icicles hang from a thin runback band).
    const double shapeMm3 = (deepestTaperedMm3(map) - 0.75 * taperedMm3) / std::sqrt(12.0);
    const double pullMm3 = (fringeMm3 + taperedMm3 + thinMm3) / std::sqrt(3.0);
    b.outlineMm3 = std::sqrt(footingMm3 * footingMm3 + unseenMm3 * unseenMm3 + shapeMm3 * shapeMm3 + pullMm3 * pullMm3);
    b.seenThroughMm3 = seenThroughSigmaMm3(seenThrough);
    if (!map.hiddenMm.empty()) {
        b.hiddenMm3 = cv::norm(map.hiddenMm, cv::NORM_L1) * map.grid.areaPerNodeMm2() / std::sqrt(3.0);
    }
    return b;
}

double expandedUncertainty(const UncertaintyBudget& b, double coverageFactor) {
    return coverageFactor * std::sqrt(b.noiseMm3 * b.noiseMm3 + b.registrationMm3 * b.registrationMm3 +
                                      b.trackingMm3 * b.trackingMm3 + b.pushMm3 * b.pushMm3 +
                                      b.biasMm3 * b.biasMm3 + b.edgeMm3 * b.edgeMm3 +
                                      b.fatteningMm3 * b.fatteningMm3 + b.scaleMm3 * b.scaleMm3 +
                                      b.outlineMm3 * b.outlineMm3 + b.seenThroughMm3 * b.seenThroughMm3 +
                                      b.hiddenMm3 * b.hiddenMm3);
}

}  // namespace icewatch::volume
