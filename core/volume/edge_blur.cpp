// How blurred a capture is, from its outline (edge_blur.hpp).
#include "core/volume/edge_blur.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "core/volume/outline_stations.hpp"
#include "core/volume/robust_statistics.hpp"

namespace icewatch::volume {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kStepPx = 0.5;

// The samples of `p` within halfSamples of its steepest rise over a pixel, the way it goes from
// end to end; empty where that window does not fit.
std::vector<float> centredOnSteepest(const std::vector<float>& p, int halfSamples, int pixel) {
    const int n = static_cast<int>(p.size());
    if (n < 2 * halfSamples + 1) return {};
    const double way = p.back() >= p.front() ? 1.0 : -1.0;
    int centre = -1;
    double steepest = 0;
    for (int i = halfSamples; i + halfSamples < n && i + pixel < n; ++i) {
        const double rise = way * (p[i + pixel] - p[i]);
        if (rise > steepest) {
            steepest = rise;
            centre = i;
        }
    }
    if (centre < 0) return {};
    return std::vector<float>(p.begin() + (centre - halfSamples), p.begin() + (centre + halfSamples + 1));
}

// Each station's blur, px, where the outline of `roi` stands out of its background. With
// `recentrePx`, each profile is taken that much longer each way and cut around its steepest rise:
// an outline grown towards an edge it does not lie on reads it centred.
std::vector<double> stationBlursPx(const cv::Mat& grey, const cv::Mat& roi, const cv::Rect& valid,
                                   const EdgeBlurOptions& o, double recentrePx = 0.0) {
    CV_Assert(grey.type() == CV_32FC1 && roi.type() == CV_8UC1 && grey.size() == roi.size());
    const int quarter = static_cast<int>(o.halfLengthPx / (2 * kStepPx));  // the outer quarters' samples
    const int pixel = static_cast<int>(1.0 / kStepPx);
    const int halfSamples = static_cast<int>(o.halfLengthPx / kStepPx);
    std::vector<double> sigmas;
    for (const OutlineStation& station : outlineStations(roi, o.stationStepPx)) {
        const double reach = o.halfLengthPx + recentrePx;
        std::vector<float> p = profileAcross(grey, valid, station.at, station.outward, reach, reach, kStepPx);
        if (recentrePx > 0 && !p.empty()) p = centredOnSteepest(p, halfSamples, pixel);
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
    return sigmas;
}

}  // namespace

double blurBeyondPixelsPx(double measuredPx) {
    return std::sqrt(std::max(0.0, measuredPx * measuredPx - kPixelSharpBlurPx * kPixelSharpBlurPx));
}

std::optional<double> outlineBlurPx(const cv::Mat& grey, const cv::Mat& roi, const cv::Rect& valid,
                                    const EdgeBlurOptions& o) {
    const std::vector<double> sigmas = stationBlursPx(grey, roi, valid, o);
    if (static_cast<int>(sigmas.size()) < o.minStations) return std::nullopt;
    return median(sigmas);
}

std::optional<double> objectBlurPx(const cv::Mat& grey, const cv::Mat& roi, const cv::Rect& valid,
                                   const EdgeBlurOptions& o) {
    if (const std::optional<double> blur = outlineBlurPx(grey, roi, valid, o)) return blur;
    // Grown a profile's half-length at a time, each station's profile taken that much longer and
    // cut around its steepest rise, so that the edge lies in its middle wherever it falls (read
    // off a profile's end, a rendered plate blurred by 1.75 px read 3.5); the growth whose
    // stations see the step most often is the edge's.
    const int stepPx = std::max(1, static_cast<int>(o.halfLengthPx));
    std::vector<double> best;
    cv::Mat grown;  // its own pixels: the caller's outline stays as drawn
    for (int growPx = stepPx; growPx <= kMaxEdgeSearchPx; growPx += stepPx) {
        cv::dilate(roi, grown, cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * growPx + 1, 2 * growPx + 1}));
        std::vector<double> sigmas = stationBlursPx(grey, grown, valid, o, o.halfLengthPx);
        if (sigmas.size() > best.size()) best = std::move(sigmas);
    }
    if (static_cast<int>(best.size()) < o.minStations) return std::nullopt;
    return median(best);
}

}  // namespace icewatch::volume
