// Per-frame image health. A burst frame that is dark (night, a covered lens), saturated (sun in
// the lens), blurred (droplets, focus) or without contrast (fog, frost on the window) gives the
// matcher nothing reliable, so it is dropped before it costs a match and before it can pull the
// burst median. The figures are cheap statistics on purpose: they run on every frame.
#include "core/health/image_health.hpp"

#include <algorithm>
#include <cstdio>

#include <opencv2/imgproc.hpp>

#include "core/common/error.hpp"

namespace icewatch::health {

namespace {
std::string figure(double value, int decimals = 1) {
    char text[48];
    std::snprintf(text, sizeof text, "%.*f", decimals, value);
    return text;
}

// A figure beside the limit it failed: to one decimal, or to as many as it takes to differ from
// the limit's (1.98 against 2 is not "2.0 below 2.0").
std::string figureAgainst(double value, double limit) {
    int decimals = 1;
    while (decimals < 4 && figure(value, decimals) == figure(limit, decimals)) ++decimals;
    return figure(value, decimals);
}

// The grey level's standard deviation in the most varied tile of a kContrastTiles-square grid.
// Fog, frost on the window or a covered lens flatten every part of the view; a small object far
// off against a plain sky leaves most of the frame as flat, but not its own part (a blade 1.26 m
// away through a filmic tone curve left whole frames under 2 grey levels).
double mostVariedTileDeviation(const cv::Mat& grey) {
    constexpr int kContrastTiles = 4;
    if (grey.rows < kContrastTiles || grey.cols < kContrastTiles) {
        cv::Scalar mean, stddev;
        cv::meanStdDev(grey, mean, stddev);
        return stddev[0];
    }
    double most = 0.0;
    for (int ty = 0; ty < kContrastTiles; ++ty)
        for (int tx = 0; tx < kContrastTiles; ++tx) {
            const int x0 = grey.cols * tx / kContrastTiles, x1 = grey.cols * (tx + 1) / kContrastTiles;
            const int y0 = grey.rows * ty / kContrastTiles, y1 = grey.rows * (ty + 1) / kContrastTiles;
            cv::Scalar mean, stddev;
            cv::meanStdDev(grey(cv::Rect(x0, y0, x1 - x0, y1 - y0)), mean, stddev);
            most = std::max(most, stddev[0]);
        }
    return most;
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
    h.meanLevel = cv::mean(grey)[0];
    const double exposure = exposureScale(h.meanLevel);
    h.contrast = mostVariedTileDeviation(grey) * exposure;
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
        h.problems.push_back({"dark", "mean level " + figureAgainst(h.meanLevel, limits.minMeanLevel) + " below " +
                                          figure(limits.minMeanLevel)});
    }
    if (h.saturatedPercent > limits.maxSaturatedPercent) {
        h.problems.push_back({"saturated", figureAgainst(h.saturatedPercent, limits.maxSaturatedPercent) +
                                               " % of pixels saturated, more than " +
                                               figure(limits.maxSaturatedPercent) + " %"});
    }
    if (h.contrast < limits.minContrast) {
        h.problems.push_back({"low_contrast", "grey-level deviation " + figureAgainst(h.contrast, limits.minContrast) +
                                                  " below " + figure(limits.minContrast)});
    }
    if (h.sharpness < limits.minSharpness) {
        h.problems.push_back({"blurred", "sharpness " + figureAgainst(h.sharpness, limits.minSharpness) + " below " +
                                             figure(limits.minSharpness)});
    }
    return h;
}

}  // namespace icewatch::health
