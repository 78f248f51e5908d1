// Ice standing out of the outline, seen by what it hides (silhouette.hpp).
#include "core/volume/silhouette.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "core/volume/beyond_outline.hpp"
#include "core/volume/mask_parts.hpp"
#include "core/volume/patch_tracker.hpp"
#include "core/volume/robust_statistics.hpp"

namespace icewatch::volume {

cv::Mat unreadBackground(const cv::Mat& hidden, const cv::Mat& baselineMeasured, const cv::Mat& currentMeasured,
                         const cv::Mat& featureless) {
    cv::Mat unread;
    cv::bitwise_not(currentMeasured, unread);
    cv::bitwise_and(unread, baselineMeasured, unread);
    cv::bitwise_and(unread, hidden, unread);
    if (!featureless.empty()) cv::bitwise_or(unread, featureless, unread);
    return unread;
}

cv::Mat leftOutBackground(const cv::Mat& drawn, const cv::Mat& region, const cv::Mat& regionInCurrent, int ringPx) {
    // The ring's dilation keeps to the region's box and the ring's reach: a disc 91 px across over
    // the whole frame took 80 ms a cycle.
    cv::Mat watched = region | regionInCurrent;
    watched |= outlineRing(watched, ringPx);
    cv::Mat leftOut;
    cv::bitwise_not(watched, leftOut);
    cv::bitwise_and(leftOut, drawn, leftOut);
    return leftOut;
}

cv::Mat backgroundHidden(const cv::Mat& baselineGrey, const cv::Mat& currentGrey, const cv::Mat& where,
                         double lightRatio, double minGrey) {
    CV_Assert(baselineGrey.type() == CV_32FC1 && currentGrey.type() == CV_32FC1 && where.type() == CV_8UC1);
    CV_Assert(baselineGrey.size() == where.size() && currentGrey.size() == where.size());
    cv::Mat difference(where.size(), CV_32F, cv::Scalar(0));
    std::vector<float> differences;
    for (int y = 0; y < where.rows; ++y) {
        const auto* in = where.ptr<std::uint8_t>(y);
        const auto* b = baselineGrey.ptr<float>(y);
        const auto* c = currentGrey.ptr<float>(y);
        auto* d = difference.ptr<float>(y);
        for (int x = 0; x < where.cols; ++x) {
            // A grey image is 0 outside the window it was matched in: no picture there to compare.
            if (!in[x] || b[x] <= 0.0f || c[x] <= 0.0f) continue;
            d[x] = c[x] - static_cast<float>(lightRatio) * b[x];
            differences.push_back(d[x]);
        }
    }
    const double threshold = std::max(minGrey, 4.0 * spreadAboutZero(std::move(differences)));
    cv::Mat hidden = cv::abs(difference) > threshold;
    hidden &= where;
    // What stands in front of the background hides a patch of it, every pixel between the outline
    // and its silhouette; a pixel or two alone is the noise's tail or a JPEG block's ringing beside
    // an edge that moved (scattered along a slanted blade's outline, they were bridged into 7 %
    // of the ice that was not there). A part is kept whole when it holds a 3 x 3 block.
    cv::Mat cores;
    cv::morphologyEx(hidden, cores, cv::MORPH_OPEN, cv::getStructuringElement(cv::MORPH_RECT, {3, 3}));
    return partsHolding(hidden, cores);
}

cv::Mat featurelessBackground(const cv::Mat& grey, const cv::Mat& object, double minTextureGrey) {
    CV_Assert(grey.type() == CV_32FC1 && object.type() == CV_8UC1 && grey.size() == object.size());
    // Sums over the window of the background's pixels only: a window astride the outline reads the
    // object's edge, not the background's texture.
    // Smoothed as the trackers' images are (measurableRing's texture test reads those): the
    // sensor's noise left in an average is no texture.
    cv::Mat smooth, background, values, squares;
    cv::GaussianBlur(grey, smooth, {0, 0}, kTrackingSmoothingPx, kTrackingSmoothingPx, cv::BORDER_REFLECT);
    cv::Mat(object == 0).convertTo(background, CV_32F, 1.0 / 255.0);
    values = smooth.mul(background);
    squares = values.mul(smooth);
    const cv::Size window(9, 9);
    cv::boxFilter(background, background, -1, window, {-1, -1}, false);
    cv::boxFilter(values, values, -1, window, {-1, -1}, false);
    cv::boxFilter(squares, squares, -1, window, {-1, -1}, false);
    cv::Mat featureless = cv::Mat::zeros(grey.size(), CV_8U);
    const float minCount = 81.0f / 3.0f;
    for (int y = 0; y < grey.rows; ++y) {
        const auto* n = background.ptr<float>(y);
        const auto* s1 = values.ptr<float>(y);
        const auto* s2 = squares.ptr<float>(y);
        const auto* inObject = object.ptr<std::uint8_t>(y);
        auto* out = featureless.ptr<std::uint8_t>(y);
        for (int x = 0; x < grey.cols; ++x) {
            if (inObject[x] || n[x] < minCount) continue;
            const double mean = s1[x] / n[x];
            const double variance = std::max(0.0, s2[x] / n[x] - mean * mean);
            if (std::sqrt(variance) < minTextureGrey) out[x] = 255;
        }
    }
    return featureless;
}

cv::Mat hiddenOnGrid(const cv::Mat& hidden, const GridSpec& grid, const PlaneFrame& plane, const cv::Mat& heightMm,
                     const RigidTransform& toBaseline, const cv::Matx33d& k) {
    CV_Assert(hidden.type() == CV_8UC1 && heightMm.type() == CV_64FC1 && heightMm.rows == grid.nv && heightMm.cols == grid.nu);
    cv::Mat onGrid = cv::Mat::zeros(grid.nv, grid.nu, CV_8U);
    const cv::Matx33d back = toBaseline.rotation.t();
    for (int j = 0; j < grid.nv; ++j)
        for (int i = 0; i < grid.nu; ++i) {
            const double h = heightMm.at<double>(j, i);
            const cv::Vec3d inBaseline = plane.toCamera(grid.u0 + i * grid.du, grid.v0 + j * grid.dv, std::isnan(h) ? 0.0 : h);
            const cv::Vec3d image = k * (back * (inBaseline - toBaseline.translation));
            if (!(image[2] > 0)) continue;
            const int x = static_cast<int>(std::lround(image[0] / image[2]));
            const int y = static_cast<int>(std::lround(image[1] / image[2]));
            if (x >= 0 && y >= 0 && x < hidden.cols && y < hidden.rows && hidden.at<std::uint8_t>(y, x)) {
                onGrid.at<std::uint8_t>(j, i) = 255;
            }
        }
    return onGrid;
}

double viewObliquityDeg(const PlaneFrame& plane) {
    const double along = std::abs(cv::normalize(plane.origin).dot(plane.normal));
    return std::acos(std::min(1.0, along)) * 180.0 / CV_PI;
}

}  // namespace icewatch::volume
