// What the estimate needs of the baseline alone (baseline_model.hpp).
#include "core/volume/baseline_model.hpp"

#include "core/volume/edge_blur.hpp"

#include <cmath>
#include <optional>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "core/volume/beyond_outline.hpp"
#include "core/volume/silhouette.hpp"

namespace icewatch::volume {

TextureTrackOptions textureTrackOptions(const Parameters& p) {
    TextureTrackOptions o;
    o.patch.radiusPx = p.trackRadiusPx;
    o.stepPx = p.trackStepPx;
    o.temporalSearchPx = p.trackSearchPx;
    return o;
}

namespace {

// The region's points off its margin, where depths mix at the outline; `measured` (CV_8U) says
// which pixels they are.
std::vector<cv::Vec3d> measuredInside(const cv::Mat& roi, const cv::Mat& points, const Parameters& p, cv::Mat& measured) {
    CV_Assert(roi.type() == CV_8UC1 && points.type() == CV_32FC3 && roi.size() == points.size());
    cv::erode(roi, measured, cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * p.edgeMarginPx + 1, 2 * p.edgeMarginPx + 1}));
    std::vector<cv::Vec3d> inside;
    for (int y = 0; y < measured.rows; ++y)
        for (int x = 0; x < measured.cols; ++x) {
            const cv::Vec3f q = points.at<cv::Vec3f>(y, x);
            if (measured.at<std::uint8_t>(y, x) && !std::isnan(q[2])) inside.emplace_back(q[0], q[1], q[2]);
            else measured.at<std::uint8_t>(y, x) = 0;
        }
    return inside;
}

}  // namespace

std::optional<PlaneFrame> baselinePlane(const cv::Mat& roi, const cv::Mat& points, const Parameters& p) {
    cv::Mat measured;
    const std::vector<cv::Vec3d> inside = measuredInside(roi, points, p, measured);
    if (static_cast<int>(inside.size()) < p.minPoints) return std::nullopt;
    return fitPlane(inside);
}

BaselineModel buildBaselineModel(const cv::Mat& roi, const cv::Mat& points, const RectifiedCapture& capture,
                                 const cv::Mat& leftGrey, double focalPx, const Parameters& p) {
    BaselineModel model;
    cv::Mat measured;
    const std::vector<cv::Vec3d> measuredPoints = measuredInside(roi, points, p, measured);
    model.measuredPoints = static_cast<int>(measuredPoints.size());
    if (model.measuredPoints < p.minPoints) return model;
    model.plane = fitPlane(measuredPoints);
    model.cloud = baselineCloud(points, measured, model.plane, p);
    model.samples = baselineSamples(capture, roi, textureTrackOptions(p));
    model.ringPx = outlineGrowthPx(p, focalPx, model.plane.origin[2]);
    model.ringMask = outlineRing(roi, model.ringPx, p.edgeMarginPx);
    model.ringMeasurable = measurableRing(capture, model.ringMask, p);
    model.ring = baselineCloud(points, model.ringMeasurable, model.plane, p);
    cv::dilate(roi, model.objectGrown, cv::getStructuringElement(cv::MORPH_ELLIPSE, {5, 5}));
    model.featureless = featurelessBackground(leftGrey, model.objectGrown, p.outlineMinTextureGrey);
    model.blurPx = objectBlurPx(leftGrey, roi, cv::Rect(0, 0, leftGrey.cols, leftGrey.rows));
    return model;
}

}  // namespace icewatch::volume
