// Connected parts of a mask (mask_parts.hpp).
#include "core/volume/mask_parts.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace icewatch::volume {

cv::Mat partsHolding(const cv::Mat& mask, const cv::Mat& seeds, int connectivity) {
    CV_Assert(mask.type() == CV_8UC1 && seeds.type() == CV_8UC1 && mask.size() == seeds.size());
    cv::Mat labels;
    const int n = cv::connectedComponents(mask, labels, connectivity, CV_32S);
    std::vector<std::uint8_t> held(static_cast<std::size_t>(n), 0);
    for (int y = 0; y < labels.rows; ++y) {
        const int* label = labels.ptr<int>(y);
        const std::uint8_t* seed = seeds.ptr<std::uint8_t>(y);
        for (int x = 0; x < labels.cols; ++x)
            if (seed[x]) held[static_cast<std::size_t>(label[x])] = 1;
    }
    held[0] = 0;  // the background
    cv::Mat parts = cv::Mat::zeros(mask.size(), CV_8U);
    for (int y = 0; y < labels.rows; ++y) {
        const int* label = labels.ptr<int>(y);
        std::uint8_t* part = parts.ptr<std::uint8_t>(y);
        for (int x = 0; x < labels.cols; ++x)
            if (held[static_cast<std::size_t>(label[x])]) part[x] = 255;
    }
    return parts;
}

cv::Mat largeParts(const cv::Mat& mask, int ofLargest) {
    CV_Assert(mask.type() == CV_8UC1 && ofLargest >= 1);
    cv::Mat labels, stats, centroids;
    const int n = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8);
    int largest = 0;
    for (int k = 1; k < n; ++k) largest = std::max(largest, stats.at<int>(k, cv::CC_STAT_AREA));
    std::vector<std::uint8_t> keep(static_cast<std::size_t>(n), 0);
    for (int k = 1; k < n; ++k) keep[static_cast<std::size_t>(k)] = stats.at<int>(k, cv::CC_STAT_AREA) * ofLargest >= largest ? 255 : 0;
    cv::Mat parts(mask.size(), CV_8U);
    for (int y = 0; y < labels.rows; ++y) {
        const int* label = labels.ptr<int>(y);
        std::uint8_t* part = parts.ptr<std::uint8_t>(y);
        for (int x = 0; x < labels.cols; ++x) part[x] = keep[static_cast<std::size_t>(label[x])];
    }
    return parts;
}

cv::Mat localMean(const cv::Mat& values, const cv::Mat& where, int r) {
    cv::Mat weight, sum;
    where.convertTo(weight, CV_32F, 1.0 / 255.0);
    cv::boxFilter(values.mul(weight), sum, -1, {2 * r + 1, 2 * r + 1}, {-1, -1}, false);
    cv::boxFilter(weight, weight, -1, {2 * r + 1, 2 * r + 1}, {-1, -1}, false);
    cv::Mat mean(values.size(), CV_32F);
    for (int y = 0; y < mean.rows; ++y) {
        const float* s = sum.ptr<float>(y);
        const float* n = weight.ptr<float>(y);
        float* m = mean.ptr<float>(y);
        for (int x = 0; x < mean.cols; ++x) m[x] = n[x] > 0.5f ? s[x] / n[x] : std::nanf("");
    }
    return mean;
}

}  // namespace icewatch::volume
