// A capture as the float average of the frames that showed the same still scene (capture_average.hpp).
#include "core/volume/capture_average.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include <opencv2/imgproc.hpp>

#include "core/common/error.hpp"
#include "core/health/image_health.hpp"

namespace icewatch::volume {

namespace {

cv::Mat greyOf(const cv::Mat& frame) {
    if (frame.channels() == 1) return frame;
    cv::Mat grey;
    cv::cvtColor(frame, grey, cv::COLOR_BGR2GRAY);
    return grey;
}

// Half-size float copy, lightly smoothed: enough to see a shift or a bird, four times cheaper to
// compare, and smooth enough for a gradient step.
cv::Mat small(const cv::Mat& grey) {
    cv::Mat f, out;
    grey.convertTo(f, CV_32F);
    cv::resize(f, out, {}, 0.5, 0.5, cv::INTER_AREA);
    cv::GaussianBlur(out, out, {0, 0}, 1.0);
    return out;
}

// The global shift of `b` against `a` (full-size pixels), by one least-squares gradient step over
// the whole image: exact enough for the fractions of a pixel that matter here, and a frame that
// moved by more reads more than the limit all the same.
cv::Point2d globalShift(const cv::Mat& a, const cv::Mat& b) {
    cv::Mat gx, gy;
    cv::Sobel(a, gx, CV_32F, 1, 0, 3, 1.0 / 8.0);
    cv::Sobel(a, gy, CV_32F, 0, 1, 3, 1.0 / 8.0);
    const cv::Mat diff = b - a;
    const double xx = gx.dot(gx), xy = gx.dot(gy), yy = gy.dot(gy);
    const double bx = -gx.dot(diff), by = -gy.dot(diff);
    const double det = xx * yy - xy * xy;
    if (det <= 1e-12) return {0, 0};
    return cv::Point2d((yy * bx - xy * by) / det, (xx * by - xy * bx) / det) * 2.0;
}

std::string nameOf(const std::vector<std::string>& names, std::size_t i) {
    return i < names.size() ? names[i] : "frame " + std::to_string(i + 1);
}

// Share of pixels (percent) whose difference stands out of the difference's own noise.
double changedPercent(const cv::Mat& a, const cv::Mat& b) {
    cv::Mat diff = a - b;
    std::vector<float> values(diff.begin<float>(), diff.end<float>());
    const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
    std::nth_element(values.begin(), mid, values.end());
    const float median = *mid;
    for (float& v : values) v = std::abs(v - median);
    std::nth_element(values.begin(), mid, values.end());
    const double sigma = std::max(0.5, 1.4826 * *mid);
    const double cut = 6.0 * sigma;
    int count = 0;
    for (auto it = diff.begin<float>(); it != diff.end<float>(); ++it) count += std::abs(*it - median) > cut ? 1 : 0;
    return 100.0 * count / static_cast<double>(diff.total());
}

}  // namespace

AveragedCapture averageCapture(const std::vector<cv::Mat>& frames, const std::vector<std::string>& names,
                               const CaptureAverageOptions& o) {
    AveragedCapture out;
    if (frames.empty()) throw InvalidInput("capture: no frames");
    auto drop = [&](std::size_t i, const std::string& flag, const std::string& why) {
        out.dropped.push_back({flag, nameOf(names, i) + ": " + why});
    };
    std::vector<std::size_t> healthy;
    std::vector<cv::Mat> greys(frames.size());
    for (std::size_t i = 0; i < frames.size(); ++i) {
        if (frames[i].empty() || frames[i].depth() != CV_8U || frames[i].size() != frames.front().size()) {
            throw InvalidInput(nameOf(names, i) + ": not an 8-bit frame of the capture's size");
        }
        greys[i] = greyOf(frames[i]);
        const int half = greys[i].cols / 2;
        bool ok = true;
        for (const auto& [eye, which] : {std::pair{cv::Rect(0, 0, half, greys[i].rows), "left eye"},
                                         std::pair{cv::Rect(half, 0, half, greys[i].rows), "right eye"}}) {
            const health::ImageHealth h = health::checkImageHealth(greys[i](eye), o.health);
            if (ok && !h.ok()) {
                drop(i, h.problems.front().flag, std::string(which) + ": " + h.problems.front().reason);
                ok = false;
            }
        }
        if (ok) healthy.push_back(i);
    }
    out.framesHealthy = static_cast<int>(healthy.size());
    // The medoid of the healthy frames, by mean absolute difference.
    std::vector<cv::Mat> smalls(frames.size());
    for (std::size_t i : healthy) smalls[i] = small(greys[i]);
    std::size_t reference = healthy.empty() ? 0 : healthy.front();
    double bestSum = std::numeric_limits<double>::infinity();
    for (std::size_t i : healthy) {
        double sum = 0;
        for (std::size_t j : healthy) sum += i == j ? 0.0 : cv::norm(smalls[i], smalls[j], cv::NORM_L1);
        if (sum < bestSum) {
            bestSum = sum;
            reference = i;
        }
    }
    std::vector<std::size_t> still;
    for (std::size_t i : healthy) {
        if (i != reference) {
            const cv::Point2d shift = globalShift(smalls[reference], smalls[i]);
            if (std::hypot(shift.x, shift.y) > o.maxFrameShiftPx) {
                std::ostringstream why;
                why.precision(2);
                why << "moved " << std::hypot(shift.x, shift.y) << " px against the others (max " << o.maxFrameShiftPx << ")";
                drop(i, "moved", why.str());
                continue;
            }
            const double changed = changedPercent(smalls[reference], smalls[i]);
            if (changed > o.maxChangedPercent) {
                std::ostringstream why;
                why.precision(2);
                why << changed << " % of the image changed against the others (something passed)";
                drop(i, "disturbed", why.str());
                continue;
            }
        }
        still.push_back(i);
    }
    if (static_cast<int>(still.size()) < std::max(1, o.minFrames)) {
        out.reason = std::to_string(still.size()) + " usable frames of " + std::to_string(frames.size()) + " (" +
                     std::to_string(std::max(1, o.minFrames)) + " needed)";
        for (const DroppedFrame& d : out.dropped) out.reason += "; " + d.reason;
        return out;
    }
    out.frame = cv::Mat::zeros(frames.front().size(), CV_32F);
    for (std::size_t i : still) cv::accumulate(greys[i], out.frame);
    out.frame /= static_cast<double>(still.size());
    out.framesUsed = static_cast<int>(still.size());
    return out;
}

}  // namespace icewatch::volume
