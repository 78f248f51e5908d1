// How much the outline's covered width changed against the sky beyond the object's motion
// (outline_growth.hpp).
#include "core/volume/outline_growth.hpp"

#include "core/volume/outline_stations.hpp"
#include "core/volume/robust_statistics.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace icewatch::volume {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kStepPx = 0.5;

}  // namespace

std::optional<double> coveredWidthPx(const std::vector<float>& profile, double stepPx, int insideSamples,
                                     int skyFitSamples, double departGrey, double minContrastGrey) {
    const int n = static_cast<int>(profile.size());
    if (skyFitSamples < 3 || insideSamples < 1 || n < insideSamples + skyFitSamples + 2) return std::nullopt;
    // The sky's line over the outer samples.
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (int i = n - skyFitSamples; i < n; ++i) {
        sx += i;
        sy += profile[static_cast<std::size_t>(i)];
        sxx += static_cast<double>(i) * i;
        sxy += i * static_cast<double>(profile[static_cast<std::size_t>(i)]);
    }
    const double m = skyFitSamples, slope = (m * sxy - sx * sy) / (m * sxx - sx * sx), offset = (sy - slope * sx) / m;
    auto departure = [&](int i) { return profile[static_cast<std::size_t>(i)] - (offset + slope * i); };
    for (int i = n - skyFitSamples; i < n; ++i)
        if (std::abs(departure(i)) > departGrey) return std::nullopt;  // not sky: something stands there too
    // The object's grey against the sky: the inner samples' median departure (its texture varies).
    std::vector<double> inner(static_cast<std::size_t>(insideSamples));
    for (int i = 0; i < insideSamples; ++i) inner[static_cast<std::size_t>(i)] = departure(i);
    const double contrast = median(inner);
    if (!(std::abs(contrast) >= minContrastGrey)) return std::nullopt;
    double covered = 0;
    for (int i = insideSamples; i < n - skyFitSamples; ++i) covered += departure(i) / contrast;
    return covered * stepPx;
}

OutlineGrowth outlineGrowth(const cv::Mat& baselineGrey, const cv::Mat& currentGrey, const cv::Mat& roi,
                            const cv::Mat& featureless, const PlaneFrame& plane, const RigidTransform& toBaseline,
                            const cv::Matx33d& k, const cv::Rect& valid, const OutlineGrowthOptions& o) {
    CV_Assert(baselineGrey.type() == CV_32FC1 && currentGrey.type() == CV_32FC1 && roi.type() == CV_8UC1 &&
              featureless.type() == CV_8UC1 && baselineGrey.size() == roi.size() &&
              currentGrey.size() == roi.size() && featureless.size() == roi.size());
    OutlineGrowth out;
    const std::vector<OutlineStation> stations = outlineStations(roi, o.stationStepPx);
    if (stations.empty()) return out;
    // The object's long axis, from the region's second moments.
    const cv::Moments mo = cv::moments(roi, true);
    const double axisAngle = 0.5 * std::atan2(2.0 * mo.mu11, mo.mu20 - mo.mu02);
    const cv::Point2d major(std::cos(axisAngle), std::sin(axisAngle)), minor(-major.y, major.x);
    const double endCos = std::cos(o.endAngleDeg * kPi / 180.0);

    // A blurred edge's tails reach further: every length grows with the blur beyond the one they
    // were made for, so that the profile still holds the whole edge and the sky beyond it.
    const double scale = std::max(1.0, o.blurPx / o.blurForLengthsPx);
    const double insidePx = scale * o.insidePx, outsidePx = scale * o.outsidePx;
    const int skyFit = static_cast<int>(std::lround(scale * o.skyFitPx / kStepPx));
    const int innerSamples = static_cast<int>(std::lround(insidePx / (2 * kStepPx)));  // the inner half of the inside
    auto covered = [&](const std::vector<float>& profile) {
        return coveredWidthPx(profile, kStepPx, innerSamples, skyFit, o.departGrey, o.minObjectContrastGrey);
    };

    std::array<std::vector<double>, 2> growth;
    for (const OutlineStation& station : stations) {
        const cv::Point2d p = station.at, normal = station.outward;
        if (std::abs(normal.dot(major)) > endCos) continue;  // an end, not a long side
        // The baseline saw featureless background (sky) outside, beyond the reach of a blurred
        // edge (whose tail the featureless test takes for texture within a few pixels of it).
        if (!insideMask(featureless, p + 8.0 * scale * normal) || !insideMask(featureless, p + 0.7 * outsidePx * normal)) continue;
        const std::optional<double> before = covered(profileAcross(baselineGrey, valid, p, normal, insidePx, outsidePx, kStepPx));
        if (!before) continue;
        // The same station and its normal, moved with the object into the current capture.
        const PixelInCurrent moved = planePixelInCurrent(p, plane, toBaseline, k);
        const cv::Point2d q = moved.at;
        const double depthMm = moved.depthMm;
        cv::Point2d qNormal = planePixelInCurrent(p + normal, plane, toBaseline, k).at - q;
        if (!(cv::norm(qNormal) >= 1e-6) || !(depthMm > 0)) continue;  // NaN: past the plane
        qNormal *= 1.0 / cv::norm(qNormal);
        const std::optional<double> after = covered(profileAcross(currentGrey, valid, q, qNormal, insidePx, outsidePx, kStepPx));
        if (!after) continue;
        const int side = normal.dot(minor) > 0 ? 0 : 1;
        growth[static_cast<std::size_t>(side)].push_back((*after - *before) * depthMm / k(0, 0));
    }
    for (std::size_t side = 0; side < 2; ++side) {
        out.stations[side] = static_cast<int>(growth[side].size());
        if (!growth[side].empty()) out.medianMm[side] = median(growth[side]);
    }
    out.bothSidesChanged = out.stations[0] >= o.minStationsPerSide && out.stations[1] >= o.minStationsPerSide &&
                           std::abs(out.medianMm[0]) >= o.minChangeMm && std::abs(out.medianMm[1]) >= o.minChangeMm;
    return out;
}

}  // namespace icewatch::volume
