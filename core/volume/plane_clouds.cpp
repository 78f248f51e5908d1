// Both captures' points on the baseline's plane (plane_clouds.hpp).
#include "core/volume/plane_clouds.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "core/volume/outlier_filter.hpp"

namespace icewatch::volume {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Current points this far behind the baseline's lowest point are background, not the object.
constexpr double kBehindMm = 10.0;

}  // namespace

BaselineCloud baselineCloud(const cv::Mat& baselinePoints, const cv::Mat& measured, const PlaneFrame& plane,
                            const Parameters& p) {
    CV_Assert(baselinePoints.type() == CV_32FC3 && measured.size() == baselinePoints.size());
    BaselineCloud cloud;
    double hMin = std::numeric_limits<double>::infinity(), hMax = -hMin;
    for (int y = 0; y < measured.rows; ++y)
        for (int x = 0; x < measured.cols; ++x) {
            const cv::Vec3f q = baselinePoints.at<cv::Vec3f>(y, x);
            if (!measured.at<std::uint8_t>(y, x) || std::isnan(q[2])) continue;
            const cv::Point3d local = plane.toPlane(cv::Vec3d(q[0], q[1], q[2]));
            hMin = std::min(hMin, local.z);
            hMax = std::max(hMax, local.z);
            cloud.points.push_back(local);
            cloud.pixels.emplace_back(x, y);
        }
    cloud.lowestMm = hMin;
    cloud.highestMm = hMax;
    cloud.keep = knnKeepMask(cloud.points, p.knnK, p.knnTheta);
    return cloud;
}

PlaneClouds planeClouds(const BaselineCloud& baseline, const BaselineCloud& baselineRing, const cv::Mat& currentPoints,
                        const cv::Mat& currentOutline, const cv::Mat& currentRing, const PlaneFrame& plane,
                        const RigidTransform& toBaseline, const Parameters& p) {
    CV_Assert(currentPoints.type() == CV_32FC3 && currentOutline.size() == currentPoints.size() &&
              currentRing.size() == currentPoints.size());
    std::vector<cv::Point3d> currentList;
    std::vector<cv::Point> currentAt;
    for (int y = 0; y < currentPoints.rows; ++y)
        for (int x = 0; x < currentPoints.cols; ++x) {
            const cv::Vec3f q = currentPoints.at<cv::Vec3f>(y, x);
            if (!(currentOutline.at<std::uint8_t>(y, x) || currentRing.at<std::uint8_t>(y, x)) || std::isnan(q[2])) continue;
            const cv::Point3d local = plane.toPlane(toBaseline.apply(cv::Vec3d(q[0], q[1], q[2])));
            if (local.z < baseline.lowestMm - kBehindMm || local.z > baseline.highestMm + p.maxThicknessMm) continue;
            currentList.push_back(local);
            currentAt.emplace_back(x, y);
        }
    PlaneClouds clouds;
    // The smallest box holding every pixel of both (one pixel at the origin when both are empty).
    clouds.box = cv::boundingRect(baseline.pixels) | cv::boundingRect(currentAt);
    if (!baselineRing.pixels.empty()) clouds.box |= cv::boundingRect(baselineRing.pixels);
    if (clouds.box.empty()) clouds.box = {0, 0, 1, 1};
    clouds.baseline = cv::Mat(clouds.box.size(), CV_64FC3, cv::Scalar::all(kNaN));
    clouds.baselineRing = cv::Mat(clouds.box.size(), CV_64FC3, cv::Scalar::all(kNaN));
    clouds.current = cv::Mat(clouds.box.size(), CV_64FC3, cv::Scalar::all(kNaN));
    clouds.currentRing = cv::Mat(clouds.box.size(), CV_64FC3, cv::Scalar::all(kNaN));
    const cv::Point origin = clouds.box.tl();
    const auto keepCurrent = knnKeepMask(currentList, p.knnK, p.knnTheta);
    for (const auto& [cloud, map] : {std::pair{&baseline, &clouds.baseline}, std::pair{&baselineRing, &clouds.baselineRing}})
        for (std::size_t i = 0; i < cloud->points.size(); ++i)
            if (cloud->keep[i]) map->at<cv::Vec3d>(cloud->pixels[i] - origin) = cv::Vec3d(cloud->points[i]);
    for (std::size_t i = 0; i < currentList.size(); ++i)
        if (keepCurrent[i]) {
            cv::Mat& map = currentRing.at<std::uint8_t>(currentAt[i]) ? clouds.currentRing : clouds.current;
            map.at<cv::Vec3d>(currentAt[i] - origin) = cv::Vec3d(currentList[i]);
            ++clouds.currentPoints;
        }
    return clouds;
}

cv::Mat outlineInCurrent(const cv::Mat& roi, const PlaneFrame& plane, const RigidTransform& toBaseline,
                         const cv::Matx34d& projection, int edgeMarginPx) {
    const cv::Matx33d k = projection.get_minor<3, 3>(0, 0);
    std::vector<std::vector<cv::Point>> contours;
    cv::findContours(roi.clone(), contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
    for (auto& contour : contours) {
        std::vector<cv::Point> movedContour;
        for (const cv::Point& px : contour) {
            const cv::Point2d moved = planePixelInCurrent(cv::Point2d(px), plane, toBaseline, k).at;
            // A pixel that looks past the plane (NaN), or lands far outside the frame, has no place
            // to round to: fillPoly clips what lies beyond the frame's edge anyway.
            if (!(std::abs(moved.x) < 1e6 && std::abs(moved.y) < 1e6)) continue;
            movedContour.emplace_back(static_cast<int>(std::lround(moved.x)), static_cast<int>(std::lround(moved.y)));
        }
        contour = std::move(movedContour);
    }
    cv::Mat mask = cv::Mat::zeros(roi.size(), CV_8U);
    cv::fillPoly(mask, contours, cv::Scalar(255));
    if (edgeMarginPx > 0) {
        cv::erode(mask, mask, cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * edgeMarginPx + 1, 2 * edgeMarginPx + 1}));
    }
    return mask;
}

}  // namespace icewatch::volume
