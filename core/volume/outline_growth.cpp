// How far the outline grew against the sky beyond the object's motion (outline_growth.hpp).
#include "core/volume/outline_growth.hpp"

#include "core/volume/outline_stations.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace icewatch::volume {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kStepPx = 0.5;

}  // namespace

double skyEdgeInProfile(const std::vector<float>& profile, double stepPx, int skyFitSamples, double departGrey) {
    const int n = static_cast<int>(profile.size());
    const int pixel = static_cast<int>(std::ceil(1.0 / stepPx));
    if (skyFitSamples < 3 || n < skyFitSamples + 2 * pixel + 2) return -1;
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
        if (std::abs(departure(i)) > departGrey) return -1;  // not sky: something stands there too
    // The outermost sample that departs, the same way, for a pixel inwards: what stands there.
    int first = -1;
    double sign = 0;
    for (int i = n - skyFitSamples - 1; i >= pixel && first < 0; --i) {
        const double s = departure(i) > 0 ? 1.0 : -1.0;
        bool departs = true;
        for (int j = i; j >= i - pixel && departs; --j) departs = s * departure(j) > departGrey;
        if (departs) first = i, sign = s;
    }
    if (first < 0) return -1;
    // Its edge is where the departure is half of what it reaches within two pixels inwards: for an
    // edge the pixels average over, the same place whatever its phase on the pixel grid, its
    // contrast or its blur (a threshold near the sky's foot moves by a quarter pixel with the phase).
    double reach = 0;
    for (int j = first; j >= std::max(0, first - 2 * pixel); --j) reach = std::max(reach, sign * departure(j));
    const double half = 0.5 * reach;
    int k = first;
    while (k > 0 && sign * departure(k) < half) --k;
    while (k + 1 < n - skyFitSamples && sign * departure(k + 1) >= half) ++k;
    const double inner = sign * departure(k), outer = sign * departure(k + 1);
    const double fraction = inner > outer ? std::clamp((inner - half) / (inner - outer), 0.0, 1.0) : 0.0;
    return (k + fraction) * stepPx;
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

    const cv::Matx33d kInv = k.inv();
    const cv::Matx33d back = toBaseline.rotation.t();
    auto onPlane = [&](cv::Point2d px) {
        const cv::Vec3d ray = kInv * cv::Vec3d(px.x, px.y, 1.0);
        return cv::Vec3d((plane.normal.dot(plane.origin) / plane.normal.dot(ray)) * ray);
    };
    auto inCurrent = [&](cv::Point2d px, double* depthMm = nullptr) {
        const cv::Vec3d p = back * (onPlane(px) - toBaseline.translation);
        if (depthMm) *depthMm = p[2];
        const cv::Vec3d q = k * p;
        return cv::Point2d(q[0] / q[2], q[1] / q[2]);
    };
    auto maskAt = [](const cv::Mat& mask, cv::Point2d q) {
        const cv::Point p(static_cast<int>(std::lround(q.x)), static_cast<int>(std::lround(q.y)));
        return p.x >= 0 && p.y >= 0 && p.x < mask.cols && p.y < mask.rows && mask.at<std::uint8_t>(p) != 0;
    };
    const int skyFit = static_cast<int>(o.skyFitPx / kStepPx);
    const int innerSamples = static_cast<int>(o.insidePx / (2 * kStepPx));  // the inner half of the inside

    std::array<std::vector<double>, 2> growth;
    for (const OutlineStation& station : stations) {
        const cv::Point2d p = station.at, normal = station.outward;
        if (std::abs(normal.dot(major)) > endCos) continue;  // an end, not a long side
        // The baseline saw featureless background (sky) outside, beyond the reach of a blurred
        // edge (whose tail the featureless test takes for texture within a few pixels of it).
        if (!maskAt(featureless, p + 8.0 * normal) || !maskAt(featureless, p + 0.7 * o.outsidePx * normal)) continue;
        const std::vector<float> before = profileAcross(baselineGrey, valid, p, normal, o.insidePx, o.outsidePx, kStepPx);
        if (before.empty()) continue;
        const double edgeBefore = skyEdgeInProfile(before, kStepPx, skyFit, o.departGrey);
        if (edgeBefore < 0) continue;
        // The object stands out against the sky here, clearly enough to place its edge.
        std::vector<double> inside(before.begin(), before.begin() + innerSamples);
        std::vector<double> sky(before.end() - skyFit, before.end());
        if (std::abs(stationMedian(inside) - stationMedian(sky)) < o.minObjectContrastGrey) continue;
        // The same station and its normal, moved with the object into the current capture.
        double depthMm = 0;
        const cv::Point2d q = inCurrent(p, &depthMm);
        cv::Point2d qNormal = inCurrent(p + normal) - q;
        if (cv::norm(qNormal) < 1e-6 || depthMm <= 0) continue;
        qNormal *= 1.0 / cv::norm(qNormal);
        const std::vector<float> after = profileAcross(currentGrey, valid, q, qNormal, o.insidePx, o.outsidePx, kStepPx);
        if (after.empty()) continue;
        const double edgeAfter = skyEdgeInProfile(after, kStepPx, skyFit, o.departGrey);
        if (edgeAfter < 0) continue;
        const int side = normal.dot(minor) > 0 ? 0 : 1;
        growth[static_cast<std::size_t>(side)].push_back((edgeAfter - edgeBefore) * depthMm / k(0, 0));
    }
    for (std::size_t side = 0; side < 2; ++side) {
        out.stations[side] = static_cast<int>(growth[side].size());
        if (!growth[side].empty()) out.medianMm[side] = stationMedian(growth[side]);
    }
    out.bothSidesGrew = out.stations[0] >= o.minStationsPerSide && out.stations[1] >= o.minStationsPerSide &&
                        out.medianMm[0] >= o.minGrowthMm && out.medianMm[1] >= o.minGrowthMm;
    return out;
}

}  // namespace icewatch::volume
