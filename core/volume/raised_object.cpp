// The object standing above the background a drawn outline holds a margin of (raised_object.hpp).
#include "core/volume/raised_object.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "core/volume/height_grid.hpp"
#include "core/volume/mask_parts.hpp"
#include "core/volume/robust_statistics.hpp"

namespace icewatch::volume {

namespace {

// Trimming rounds of the ring's plane fit: the ring may cross the object where the outline cuts
// across it, or hold a stray match; after a few rounds only the background's plane is left.
constexpr int kPlaneRounds = 3;
// Points farther from the plane than this many σ are trimmed in the next round.
constexpr double kTrimSigmas = 3.0;

bool measured(const cv::Vec3f& p) { return !std::isnan(p[2]); }

// The background's plane through the ring's points, and the σ of their heights about it.
struct BackgroundPlane {
    PlaneFrame plane;
    double sigmaMm = 0;
};

BackgroundPlane fitBackgroundPlane(const std::vector<cv::Vec3d>& ring) {
    std::vector<cv::Vec3d> kept = ring;
    BackgroundPlane out;
    for (int round = 0; round < kPlaneRounds; ++round) {
        out.plane = fitPlane(kept);
        std::vector<double> residual;
        residual.reserve(ring.size());
        for (const cv::Vec3d& p : ring) residual.push_back(std::abs(out.plane.toPlane(p).z));
        out.sigmaMm = spreadAboutZero(residual);
        std::vector<cv::Vec3d> next;
        for (std::size_t i = 0; i < ring.size(); ++i)
            if (residual[i] <= kTrimSigmas * out.sigmaMm) next.push_back(ring[i]);
        if (next.size() < 3) break;
        kept = std::move(next);
    }
    return out;
}

}  // namespace

RaisedObject objectAboveItsBackground(const cv::Mat& outline, const cv::Mat& points, const RaisedObjectOptions& o) {
    CV_Assert(outline.type() == CV_8UC1 && points.type() == CV_32FC3 && outline.size() == points.size());
    RaisedObject out;
    out.object = outline.clone();
    const int outlinePixels = cv::countNonZero(outline);
    if (outlinePixels == 0) return out;

    // The background's plane, from the ring just outside the outline where the matcher measured it.
    cv::Mat ring;
    cv::dilate(outline, ring, cv::getStructuringElement(cv::MORPH_RECT, {2 * o.ringPx + 1, 2 * o.ringPx + 1}));
    ring &= ~outline;
    std::vector<cv::Vec3d> ringPoints;
    const int ringPixels = cv::countNonZero(ring);
    for (int y = 0; y < ring.rows; ++y) {
        const auto* r = ring.ptr<std::uint8_t>(y);
        const auto* p = points.ptr<cv::Vec3f>(y);
        for (int x = 0; x < ring.cols; ++x)
            if (r[x] && measured(p[x])) ringPoints.emplace_back(p[x]);
    }
    if (static_cast<int>(ringPoints.size()) < o.minRingPoints ||
        static_cast<double>(ringPoints.size()) < o.minRingMeasured * ringPixels) {
        return out;
    }
    const BackgroundPlane background = fitBackgroundPlane(ringPoints);
    const double toleranceMm = std::max(o.toleranceSigmas * background.sigmaMm, o.minToleranceMm);

    // Heights above the background's plane, towards the camera; NaN unmeasured.
    cv::Mat height(points.size(), CV_64F, cv::Scalar(std::nan("")));
    cv::Mat onPlane(points.size(), CV_8U, cv::Scalar(0));
    for (int y = 0; y < points.rows; ++y) {
        const auto* p = points.ptr<cv::Vec3f>(y);
        auto* h = height.ptr<double>(y);
        auto* on = onPlane.ptr<std::uint8_t>(y);
        for (int x = 0; x < points.cols; ++x) {
            if (!measured(p[x])) continue;
            h[x] = background.plane.toPlane(cv::Vec3d(p[x])).z;
            if (std::abs(h[x]) <= toleranceMm) on[x] = 255;
        }
    }
    // The margin: what the background outside reaches inside through pixels on its plane.
    const cv::Mat margin = partsHolding(onPlane & (outline | ring), onPlane & ring, 4) & outline;
    if (cv::countNonZero(margin) < o.minMarginShare * outlinePixels) return out;
    const cv::Mat object = largeParts(outline & ~margin, kSpeckShareOfLargest);
    if (cv::countNonZero(object) == 0) return out;

    // Where the object meets the margin, past the matcher's smeared edge: does it stand above it?
    cv::Mat distance;
    cv::distanceTransform(~margin, distance, cv::DIST_L2, cv::DIST_MASK_PRECISE);
    std::vector<double> step;
    for (int y = 0; y < object.rows; ++y) {
        const auto* in = object.ptr<std::uint8_t>(y);
        const auto* d = distance.ptr<float>(y);
        const auto* h = height.ptr<double>(y);
        for (int x = 0; x < object.cols; ++x)
            if (in[x] && d[x] >= o.stepFromPx && d[x] <= o.stepToPx && !std::isnan(h[x])) step.push_back(h[x]);
    }
    if (step.empty()) return out;
    out.stepMm = median(std::move(step));
    if (out.stepMm < std::max(o.minStepMm, o.stepTolerances * toleranceMm)) return out;
    out.object = object;
    out.backgroundPercent = 100.0 * (outlinePixels - cv::countNonZero(object)) / outlinePixels;
    return out;
}

}  // namespace icewatch::volume
