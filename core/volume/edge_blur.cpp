// How blurred a capture is, from its outline (edge_blur.hpp).
#include "core/volume/edge_blur.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/volume/outline_stations.hpp"
#include "core/volume/robust_statistics.hpp"

namespace icewatch::volume {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kStepPx = 0.5;

}  // namespace

double blurBeyondPixelsPx(double measuredPx) {
    return std::sqrt(std::max(0.0, measuredPx * measuredPx - kPixelSharpBlurPx * kPixelSharpBlurPx));
}

std::optional<double> outlineBlurPx(const cv::Mat& grey, const cv::Mat& roi, const cv::Rect& valid,
                                    const EdgeBlurOptions& o) {
    CV_Assert(grey.type() == CV_32FC1 && roi.type() == CV_8UC1 && grey.size() == roi.size());
    const int quarter = static_cast<int>(o.halfLengthPx / (2 * kStepPx));  // the outer quarters' samples
    const int pixel = static_cast<int>(1.0 / kStepPx);
    std::vector<double> sigmas;
    for (const OutlineStation& station : outlineStations(roi, o.stationStepPx)) {
        const std::vector<float> p =
            profileAcross(grey, valid, station.at, station.outward, o.halfLengthPx, o.halfLengthPx, kStepPx);
        if (p.empty()) continue;
        const std::vector<double> inside(p.begin(), p.begin() + quarter), outside(p.end() - quarter, p.end());
        const double step = median(outside) - median(inside);
        if (std::abs(step) < o.minStepGrey) continue;
        // The steepest rise over a pixel, the way the step goes, between the outer quarters.
        double slope = 0;
        for (std::size_t i = static_cast<std::size_t>(quarter); i + pixel < p.size() - quarter; ++i) {
            slope = std::max(slope, (step > 0 ? 1.0 : -1.0) * (p[i + pixel] - p[i]));
        }
        if (slope <= 0) continue;
        sigmas.push_back(std::abs(step) / (slope * std::sqrt(2.0 * kPi)));
    }
    if (static_cast<int>(sigmas.size()) < o.minStations) return std::nullopt;
    return median(sigmas);
}

}  // namespace icewatch::volume
