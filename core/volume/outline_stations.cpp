// Places along the outline, and profiles across it (outline_stations.hpp).
#include "core/volume/outline_stations.hpp"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

namespace icewatch::volume {

namespace {

double bilinear(const cv::Mat& image, double x, double y) {
    const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
    const double fx = x - x0, fy = y - y0;
    const float* r0 = image.ptr<float>(y0);
    const float* r1 = image.ptr<float>(y0 + 1);
    return (1 - fy) * ((1 - fx) * r0[x0] + fx * r0[x0 + 1]) + fy * ((1 - fx) * r1[x0] + fx * r1[x0 + 1]);
}

}  // namespace

bool insideMask(const cv::Mat& mask, cv::Point2d at) {
    const cv::Point p(static_cast<int>(std::lround(at.x)), static_cast<int>(std::lround(at.y)));
    return p.x >= 0 && p.y >= 0 && p.x < mask.cols && p.y < mask.rows && mask.at<std::uint8_t>(p) != 0;
}

std::vector<OutlineStation> outlineStations(const cv::Mat& roi, int stepPx) {
    CV_Assert(roi.type() == CV_8UC1 && stepPx >= 1);
    std::vector<std::vector<cv::Point>> contours;
    cv::findContours(roi.clone(), contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
    std::vector<OutlineStation> stations;
    if (contours.empty()) return stations;
    const auto& contour = *std::max_element(contours.begin(), contours.end(), [](const auto& a, const auto& b) {
        return cv::contourArea(a) < cv::contourArea(b);
    });
    const int n = static_cast<int>(contour.size());
    if (n < 16) return stations;
    for (int i = 0; i < n; i += stepPx) {
        const cv::Point2d p = contour[static_cast<std::size_t>(i)];
        const cv::Point2d t = cv::Point2d(contour[static_cast<std::size_t>((i + 3) % n)]) -
                              cv::Point2d(contour[static_cast<std::size_t>((i - 3 + n) % n)]);
        const double length = cv::norm(t);
        if (length < 1e-6) continue;
        cv::Point2d normal(t.y / length, -t.x / length);
        if (insideMask(roi, p + 3.0 * normal)) normal = -normal;
        if (insideMask(roi, p + 3.0 * normal) || !insideMask(roi, p - 3.0 * normal)) continue;  // a corner
        stations.push_back({p, normal});
    }
    return stations;
}

std::vector<float> profileAcross(const cv::Mat& image, const cv::Rect& valid, cv::Point2d centre, cv::Point2d normal,
                                 double insidePx, double outsidePx, double stepPx) {
    CV_Assert(image.type() == CV_32FC1);
    const cv::Point2d tangent(-normal.y, normal.x);
    const int samples = static_cast<int>(std::lround((insidePx + outsidePx) / stepPx)) + 1;
    std::vector<float> profile(static_cast<std::size_t>(samples));
    const cv::Rect inImage = valid & cv::Rect(0, 0, image.cols, image.rows);
    const cv::Rect2d inner(inImage.x, inImage.y, inImage.width - 1.001, inImage.height - 1.001);
    for (int i = 0; i < samples; ++i) {
        const double s = -insidePx + i * stepPx;
        double sum = 0;
        for (int line = -1; line <= 1; ++line) {
            const cv::Point2d q = centre + s * normal + line * tangent;
            if (!inner.contains(q)) return {};
            sum += bilinear(image, q.x, q.y);
        }
        profile[static_cast<std::size_t>(i)] = static_cast<float>(sum / 3.0);
    }
    return profile;
}

}  // namespace icewatch::volume
