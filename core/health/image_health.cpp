// Per-frame image health. A burst frame that is dark (night, a covered lens), saturated (sun in
// the lens), blurred (droplets, focus) or without contrast (fog, frost on the window) gives the
// matcher nothing reliable, so it is dropped before it costs a match and before it can pull the
// burst median. The figures are cheap global statistics on purpose: they run on every frame.
#include "core/health/image_health.hpp"

#include <algorithm>
#include <cstdio>

#include <opencv2/imgproc.hpp>

#include "core/common/error.hpp"

namespace icewatch::health {

namespace {
std::string figure(double value) {
    char text[32];
    std::snprintf(text, sizeof text, "%.1f", value);
    return text;
}
}  // namespace

ImageHealth checkImageHealth(const cv::Mat& image, const config::ImageHealthConfig& limits) {
    if (image.empty() || image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3)) {
        throw InvalidInput("image health: need a non-empty 8-bit grey or BGR image");
    }
    cv::Mat grey;
    if (image.channels() == 3) {
        cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
    } else {
        grey = image;
    }
    ImageHealth h;
    cv::Scalar mean, stddev;
    cv::meanStdDev(grey, mean, stddev);
    h.meanLevel = mean[0];
    const double exposure = exposureScale(h.meanLevel);
    h.contrast = stddev[0] * exposure;
    h.saturatedPercent = 100.0 * cv::countNonZero(grey >= 250) / static_cast<double>(grey.total());
    // Sharpness at quarter scale: sensor noise and JPEG blocking average out there while edges of
    // the blade survive, so the figure tells blur apart from a noisy but sharp image.
    cv::Mat half, quarter, laplacian;
    cv::pyrDown(grey, half);
    cv::pyrDown(half, quarter);
    cv::Laplacian(quarter, laplacian, CV_32F, 1);
    // The image border is left out: the reflected border makes a kink in any shading.
    const cv::Rect inner(1, 1, std::max(1, laplacian.cols - 2), std::max(1, laplacian.rows - 2));
    cv::Scalar lapMean, lapStddev;
    cv::meanStdDev(laplacian(inner & cv::Rect(0, 0, laplacian.cols, laplacian.rows)), lapMean, lapStddev);
    h.sharpness = lapStddev[0] * lapStddev[0] * exposure * exposure;

    if (h.meanLevel < limits.minMeanLevel) {
        h.problems.push_back({"dark", "mean level " + figure(h.meanLevel) + " below " + figure(limits.minMeanLevel)});
    }
    if (h.saturatedPercent > limits.maxSaturatedPercent) {
        h.problems.push_back({"saturated", figure(h.saturatedPercent) + " % of pixels saturated, more than " +
                                               figure(limits.maxSaturatedPercent) + " %"});
    }
    if (h.contrast < limits.minContrast) {
        h.problems.push_back({"low_contrast", "grey-level deviation " + figure(h.contrast) + " below " +
                                                  figure(limits.minContrast)});
    }
    if (h.sharpness < limits.minSharpness) {
        h.problems.push_back({"blurred", "sharpness " + figure(h.sharpness) + " below " + figure(limits.minSharpness)});
    }
    return h;
}

}  // namespace icewatch::health
