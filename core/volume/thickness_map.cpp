// Ice thickness on the plane's grid (thickness_map.hpp).
#include "core/volume/thickness_map.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "core/volume/beyond_outline.hpp"
#include "core/volume/robust_statistics.hpp"

namespace icewatch::volume {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// How wide the ring's outer edge is taken, in pixels: wide enough that the grid's nodes (a cell
// may span more than a pixel) sample it along its whole length.
constexpr int kRingEdgePx = 3;

// The last kRingEdgePx pixels of `ring` away from `roi`: what borders neither the ring nor the gap
// of `gapPx` between it and the outline. The frame's own edge does not count (erode treats what
// lies past it as set).
cv::Mat ringOuterEdge(const cv::Mat& roi, const cv::Mat& ring, int gapPx) {
    cv::Mat watched;
    cv::dilate(roi, watched, cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * gapPx + 3, 2 * gapPx + 3}));
    watched |= ring;
    cv::erode(watched, watched, cv::getStructuringElement(cv::MORPH_RECT, {2 * kRingEdgePx + 1, 2 * kRingEdgePx + 1}));
    return ring & ~watched;
}

// Where the baseline saw featureless background (`bare`) and the current capture hides it: the ice
// tapered from the outline's (taperedIce), into map.thickness, map.beyond and map.tapered.
void addTaperedIce(ThicknessMap& map, const cv::Mat& rise, const cv::Mat& bare, const HiddenBackground& hidden,
                   const PlaneFrame& plane, const cv::Matx33d& k, double minRiseMm, int gapNodes, int fringeNodes) {
    const GridSpec& grid = map.grid;
    // As high on the outline as the ice on the region's nearest nodes, averaged over a few.
    cv::Mat edge = map.thickness.clone();
    edge.setTo(kNaN, map.inside == 0);
    edge = finiteBoxMean(edge, 2);
    fillFromNearest(edge, cv::Mat(grid.nv, grid.nu, CV_8U, cv::Scalar(255)));
    // A node is looked for at the height of the ice on the outline above it: ice on the outline
    // seen obliquely hides the background beyond it without standing there, and a taller top
    // shows farther out.
    cv::Mat iceTop = map.thickness.clone();
    iceTop.setTo(0.0, (map.inside == 0) | (iceTop != iceTop));
    cv::dilate(iceTop, iceTop, cv::getStructuringElement(cv::MORPH_RECT, {2 * gapNodes + 5, 2 * gapNodes + 5}));
    iceTop = cv::max(iceTop, cv::max(edge, 0.0));
    iceTop += map.baselineHeight;
    const cv::Mat hiddenNodes = hiddenOnGrid(hidden.pixels, grid, plane, iceTop, hidden.toBaseline, k) & bare;
    // Next to the outline the background is not compared where the baseline showed the object
    // (its outline grown by 2 px, and moved): about the ring's own gap and those 2 px.
    const int hiddenGapNodes = gapNodes + 2;
    const cv::Mat measured = map.beyond & (rise == rise);  // NaN != NaN
    // Over featureless background a rise has no footing but the outline's nearest measured
    // surface, some way up a rounded edge: the ice's height on the outline and the background it
    // hides say more. Over a textured one (a table) the rise is measured from it.
    const cv::Mat seenUnder = measured & ~bare;
    // The background's first pixels next to the outline are the object's (grown, as the window
    // leaves it out): bare there when bare beyond them.
    cv::Mat nearBare;
    cv::dilate(bare, nearBare, cv::getStructuringElement(cv::MORPH_RECT, {2 * hiddenGapNodes + 1, 2 * hiddenGapNodes + 1}));
    cv::Mat tapered(grid.nv, grid.nu, CV_64F, cv::Scalar(kNaN));
    map.thinBeyondMm = cv::Mat(grid.nv, grid.nu, CV_64F, cv::Scalar(kNaN));
    map.tapered = taperedIce(hiddenNodes | measured, map.inside, edge, minRiseMm, hiddenGapNodes, tapered,
                             &map.thinBeyondMm) &
                  nearBare & ~seenUnder;
    map.thinBeyondMm.setTo(kNaN, ~(nearBare & ~seenUnder));
    tapered.copyTo(map.thickness, map.tapered);
    map.beyond |= map.tapered;
    map.taperedNodes = cv::countNonZero(map.tapered);
    // Where it stands (or what hides the background where the outline reads too thin for ice),
    // the outline's surface was read against it now and against the sky before: the ice inside
    // within the matcher's pull of it (its uncertainty, uncertainty.hpp).
    const cv::Mat standing = map.tapered | (map.thinBeyondMm == map.thinBeyondMm);  // NaN != NaN
    if (fringeNodes > 0 && cv::countNonZero(standing) > 0) {
        cv::dilate(standing, map.fringe,
                   cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * fringeNodes + 1, 2 * fringeNodes + 1}));
        map.fringe &= map.inside & map.onIce;
    }
}

}  // namespace

OutlineGrid outlineGrid(const cv::Mat& roi, const PlaneFrame& plane, const cv::Matx33d& k, double cellMm) {
    std::vector<std::vector<cv::Point>> contours;
    cv::findContours(roi.clone(), contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
    const cv::Matx33d kInv = k.inv();
    double uMin = 1e18, uMax = -1e18, vMin = 1e18, vMax = -1e18;
    for (const auto& contour : contours)
        for (const cv::Point& px : contour) {
            const std::optional<cv::Vec3d> hit = plane.rayHit(kInv * cv::Vec3d(px.x, px.y, 1.0));
            if (!hit) {
                return {std::nullopt, "the outline's pixel (" + std::to_string(px.x) + ", " + std::to_string(px.y) +
                                          ") looks past the region's plane"};
            }
            const cv::Point3d local = plane.toPlane(*hit);
            uMin = std::min(uMin, local.x);
            uMax = std::max(uMax, local.x);
            vMin = std::min(vMin, local.y);
            vMax = std::max(vMax, local.y);
        }
    return gridOver(uMin, uMax, vMin, vMax, cellMm);
}

ThicknessMap thicknessMap(const GridSpec& grid, const PlaneClouds& clouds, const cv::Mat& roi, const cv::Mat& ring,
                          const cv::Mat& possibleIce, const PlaneFrame& plane, const cv::Matx33d& k,
                          const Parameters& p, const HiddenBackground& hidden, const cv::Mat& seenThrough) {
    CV_Assert(roi.type() == CV_8UC1 && possibleIce.size() == roi.size() && ring.size() == roi.size());
    CV_Assert(seenThrough.empty() || seenThrough.size() == roi.size());
    ThicknessMap map;
    map.grid = grid;
    const StepOptions steps{p.occlusionSlope, p.occlusionStepMm};
    const cv::Mat baselineHeight = interpolateLattice(clouds.baseline, grid, steps);
    const cv::Mat currentHeight = interpolateLattice(clouds.current, grid, steps);
    // The same with every band hidden along the line of sight ended in a wall: the least each
    // surface may be where the camera did not see it.
    const cv::Point3d eye = plane.toPlane(cv::Vec3d(0, 0, 0));
    const StepOptions walls{p.occlusionSlope, p.occlusionStepMm, true, cv::Vec3d(eye.x, eye.y, eye.z)};
    const cv::Mat baselineLeast = interpolateLattice(clouds.baseline, grid, walls);
    const cv::Mat currentLeast = interpolateLattice(clouds.current, grid, walls);
    map.hiddenMm = cv::Mat(grid.nv, grid.nu, CV_64F, cv::Scalar(0.0));
    const bool anyRing = cv::countNonZero(ring) > 0;
    const cv::Mat none(grid.nv, grid.nu, CV_64F, cv::Scalar(kNaN));
    const cv::Mat ringHeight = anyRing && !clouds.baselineRing.empty() ? interpolateLattice(clouds.baselineRing, grid, steps) : none;
    const cv::Mat currentRingHeight =
        anyRing && !clouds.currentRing.empty() ? interpolateLattice(clouds.currentRing, grid, steps) : none;
    cv::Mat rise(grid.nv, grid.nu, CV_64F, cv::Scalar(kNaN));
    // Per ring node, half of how far the outline stands off the background seen there (0 where it
    // does not): the band in which the underside of ice in front of it may lie.
    cv::Mat standoffHalfMm(grid.nv, grid.nu, CV_64F, cv::Scalar(0.0));
    cv::Mat bare(grid.nv, grid.nu, CV_8U, cv::Scalar(0));  // outside the region, background nothing is measured in front of
    std::vector<double> seenRises;
    map.baselineHeight = baselineHeight.clone();
    fillFromNearest(map.baselineHeight, cv::Mat(grid.nv, grid.nu, CV_8U, cv::Scalar(255)));

    map.inside = cv::Mat(grid.nv, grid.nu, CV_8U, cv::Scalar(0));
    map.onIce = cv::Mat(grid.nv, grid.nu, CV_8U, cv::Scalar(0));
    map.ringEdge = cv::Mat(grid.nv, grid.nu, CV_8U, cv::Scalar(0));
    const cv::Mat ringEdgePixels = anyRing ? ringOuterEdge(roi, ring, p.edgeMarginPx) : cv::Mat::zeros(roi.size(), CV_8U);
    map.thickness = cv::Mat(grid.nv, grid.nu, CV_64F, cv::Scalar(kNaN));
    if (!seenThrough.empty()) map.seenThrough = cv::Mat(grid.nv, grid.nu, CV_8U, cv::Scalar(0));
    for (int j = 0; j < grid.nv; ++j)
        for (int i = 0; i < grid.nu; ++i) {
            const double h = map.baselineHeight.at<double>(j, i);
            const cv::Vec3d image = k * plane.toCamera(grid.u0 + i * grid.du, grid.v0 + j * grid.dv, std::isnan(h) ? 0.0 : h);
            const int x = static_cast<int>(std::lround(image[0] / image[2]));
            const int y = static_cast<int>(std::lround(image[1] / image[2]));
            if (x < 0 || y < 0 || x >= roi.cols || y >= roi.rows) continue;
            if (!hidden.unread.empty() && hidden.unread.at<std::uint8_t>(y, x)) bare.at<std::uint8_t>(j, i) = 255;
            if (ring.at<std::uint8_t>(y, x)) {
                if (ringEdgePixels.at<std::uint8_t>(y, x)) map.ringEdge.at<std::uint8_t>(j, i) = 255;
                // From what the baseline saw there (a table, more of a plate than the outline
                // drawn on it, the matcher's fringe), or from the outline's nearest surface where
                // it saw sky.
                const double seen = ringHeight.at<double>(j, i);
                const double current = currentRingHeight.at<double>(j, i);
                double footing = std::isnan(seen) ? h : seen;
                if (!std::isnan(seen) && h - seen > p.outlineStandoffMm) {
                    // The outline stands off what the baseline saw beyond it (a blade on trestles,
                    // a whole airfoil's edge above its table): ice in front of it shows its top,
                    // and its underside may reach down to that background or stop at the
                    // outline's height. The middle, and the band its hidden half (hiddenMm).
                    standoffHalfMm.at<double>(j, i) = 0.5 * (h - seen);
                    footing = seen + standoffHalfMm.at<double>(j, i);
                }
                rise.at<double>(j, i) = current - footing;
                if (!std::isnan(seen) && !std::isnan(current)) seenRises.push_back(current - seen);
                continue;
            }
            if (!roi.at<std::uint8_t>(y, x)) continue;
            map.inside.at<std::uint8_t>(j, i) = 255;
            ++map.insideNodes;
            if (!possibleIce.at<std::uint8_t>(y, x)) {
                map.thickness.at<double>(j, i) = 0.0;
                continue;
            }
            map.onIce.at<std::uint8_t>(j, i) = 255;
            if (!seenThrough.empty()) map.seenThrough.at<std::uint8_t>(j, i) = seenThrough.at<std::uint8_t>(y, x);
            ++map.iceNodes;
            map.thickness.at<double>(j, i) = currentHeight.at<double>(j, i) - baselineHeight.at<double>(j, i);
            const double least = currentLeast.at<double>(j, i) - baselineLeast.at<double>(j, i);
            const double bridged = map.thickness.at<double>(j, i) - least;
            if (std::isfinite(bridged)) map.hiddenMm.at<double>(j, i) = bridged;
        }
    // Where both captures saw a surface the rise is a difference of two measurements, as inside,
    // and its noise, read off its spread (robustly: the ice is the minority), must not pass for ice:
    // single-frame SGBM on the plate around a block read 54 000 mm3 of it at the 2 mm threshold.
    const double noiseMm = spreadAboutMedian(std::move(seenRises));
    const double minRiseMm = std::max(p.outlineIceMinMm, 4.0 * noiseMm);
    // The ring starts edge_margin_px outside the outline: that many nodes may lie between the two.
    const double pixelMm = plane.origin[2] / k(0, 0);
    const int gapNodes = static_cast<int>(std::ceil(p.edgeMarginPx * pixelMm / std::min(grid.du, grid.dv)));
    map.beyond = iceBeyondOutline(rise, map.inside, minRiseMm, gapNodes, noiseMm);
    rise.copyTo(map.thickness, map.beyond);
    standoffHalfMm.copyTo(map.hiddenMm, map.beyond & (standoffHalfMm > 0));
    if (!hidden.pixels.empty()) {
        const int fringeNodes = static_cast<int>(std::ceil(p.outlineFringePx * pixelMm / std::min(grid.du, grid.dv)));
        addTaperedIce(map, rise, bare, hidden, plane, k, minRiseMm, gapNodes, fringeNodes);
    }
    map.onIce.setTo(255, map.beyond);
    map.beyondNodes = cv::countNonZero(map.beyond);
    map.beyondAtRingEdgeNodes =
        iceAtRingEdge(map.beyond, map.tapered, map.thickness, map.inside, map.ringEdge, minRiseMm, gapNodes);
    map.iceNodes += map.beyondNodes;
    map.filledNodes = fillFromNearest(map.thickness, map.onIce);
    return map;
}

IceSummary summarise(const ThicknessMap& map, Integration method) {
    IceSummary s;
    const double node = map.grid.areaPerNodeMm2();
    s.volumeMm3 = integrate(map.thickness, map.grid, method);
    s.areaMm2 = map.insideNodes * node;
    s.iceAreaMm2 = map.iceNodes * node;
    if (map.beyondNodes > 0) {
        cv::Mat beyond(map.thickness.size(), CV_64F, cv::Scalar(0));
        map.thickness.copyTo(beyond, map.beyond);
        s.beyondOutlineMm3 = integrate(beyond, map.grid, method);
        s.beyondOutlineAreaMm2 = map.beyondNodes * node;
    }
    s.meanThicknessMm = s.areaMm2 > 0 ? s.volumeMm3 / s.areaMm2 : 0.0;
    s.smoothedMm = finiteBoxMean(map.thickness, 2);
    s.smoothedMm.setTo(kNaN, (map.inside | map.beyond) == 0);
    for (int j = 0; j < s.smoothedMm.rows; ++j)
        for (int i = 0; i < s.smoothedMm.cols; ++i) {
            const double t = s.smoothedMm.at<double>(j, i);
            if (!std::isnan(t)) s.maxThicknessMm = std::max(s.maxThicknessMm, t);
        }
    return s;
}

cv::Mat thicknessInImage(const cv::Mat& thickness, const GridSpec& grid, const PlaneFrame& plane,
                         const RigidTransform& toBaseline, const cv::Matx33d& kInv, const cv::Mat& outline) {
    cv::Mat image(outline.size(), CV_32F, cv::Scalar(std::numeric_limits<float>::quiet_NaN()));
    const cv::Vec3d centre = toBaseline.translation;
    for (int y = 0; y < outline.rows; ++y)
        for (int x = 0; x < outline.cols; ++x) {
            if (!outline.at<std::uint8_t>(y, x)) continue;
            const cv::Vec3d ray = toBaseline.rotation * (kInv * cv::Vec3d(x, y, 1.0));
            const std::optional<cv::Vec3d> hit = plane.rayHit(ray, centre);
            if (!hit) continue;
            const cv::Point3d local = plane.toPlane(*hit);
            const int i = static_cast<int>(std::lround((local.x - grid.u0) / grid.du));
            const int j = static_cast<int>(std::lround((local.y - grid.v0) / grid.dv));
            if (i >= 0 && j >= 0 && i < grid.nu && j < grid.nv) {
                image.at<float>(y, x) = static_cast<float>(thickness.at<double>(j, i));
            }
        }
    return image;
}

}  // namespace icewatch::volume
