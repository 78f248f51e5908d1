// The region of interest: the object's outline, so sky, tower and background never count as ice.
// A polygon drawn at commissioning (in the camera's own pixels) is mapped through the
// rectification; without one the outline is segmented from the baseline's depth and, where the
// background is featureless, from its look.
#include "core/volume/roi.hpp"

#include <cmath>
#include <fstream>
#include <optional>

#include <nlohmann/json.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "core/common/error.hpp"
#include "core/volume/drawn_outline.hpp"
#include "core/volume/mask_parts.hpp"

namespace icewatch::volume {

namespace {

// The largest 8-connected part of `mask` (CV_8U) with its holes filled (its outer contour drawn
// filled); all zero when `mask` is.
cv::Mat largestPartFilled(const cv::Mat& mask) {
    cv::Mat labels, stats, centroids;
    const int n = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8);
    int best = 0, bestArea = 0;
    for (int i = 1; i < n; ++i) {
        if (stats.at<int>(i, cv::CC_STAT_AREA) > bestArea) {
            bestArea = stats.at<int>(i, cv::CC_STAT_AREA);
            best = i;
        }
    }
    cv::Mat part = cv::Mat::zeros(mask.size(), CV_8U);
    if (best == 0) return part;
    part.setTo(255, labels == best);
    std::vector<std::vector<cv::Point>> contours;
    cv::findContours(part.clone(), contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
    cv::drawContours(part, contours, -1, cv::Scalar(255), cv::FILLED);
    return part;
}

// Whether `region` (CV_8U) is cut out of a surface that goes on beyond it: most of the pixels
// just outside it (1-4 px, with a depth) lie within kContinuesMm of the region's depth beside them.
// At an object's edge the depth steps to what is behind it; where the depth band cut a table or a
// wall the object lies on, the surface goes on.
bool surfaceContinues(const cv::Mat& region, const cv::Mat& points) {
    constexpr double kContinuesMm = 30.0;
    constexpr int kBesidePx = 6;
    cv::Mat z(points.size(), CV_32F);
    cv::extractChannel(points, z, 2);
    const cv::Mat measured = z == z;  // NaN != NaN
    const cv::Mat inside = region & measured;
    cv::Mat zInside = cv::Mat::zeros(z.size(), CV_32F);
    z.copyTo(zInside, inside);
    const cv::Mat besideMean = localMean(zInside, inside, kBesidePx);
    cv::Mat outside, skip;
    cv::dilate(region, outside, cv::getStructuringElement(cv::MORPH_RECT, {9, 9}));
    cv::dilate(region, skip, cv::getStructuringElement(cv::MORPH_RECT, {3, 3}));
    outside &= ~skip & measured;
    int beside = 0, continuing = 0;
    for (int y = 0; y < z.rows; ++y)
        for (int x = 0; x < z.cols; ++x) {
            const float mean = besideMean.at<float>(y, x);
            if (!outside.at<std::uint8_t>(y, x) || std::isnan(mean)) continue;
            ++beside;
            if (std::abs(z.at<float>(y, x) - mean) < kContinuesMm) ++continuing;
        }
    return beside > 0 && 2 * continuing > beside;
}

// The inverse depth of the plane best fitting the points of `where` (CV_8U), as a x + b y + c of
// the pixel (x, y): a plane's inverse depth is affine in the pixel. Every 4th pixel each way is
// enough for three numbers. None when fewer than kMinPoints are measured or the fit is singular.
std::optional<cv::Vec3d> inverseDepthPlane(const cv::Mat& points, const cv::Mat& where) {
    constexpr int kStepPx = 4;
    constexpr int kMinPoints = 100;
    cv::Matx33d normal = cv::Matx33d::zeros();
    cv::Vec3d right(0, 0, 0);
    int n = 0;
    for (int y = kStepPx / 2; y < points.rows; y += kStepPx) {
        const auto* row = points.ptr<cv::Vec3f>(y);
        const auto* in = where.ptr<std::uint8_t>(y);
        for (int x = kStepPx / 2; x < points.cols; x += kStepPx) {
            const float z = row[x][2];
            if (!in[x] || std::isnan(z) || z <= 0) continue;
            const cv::Vec3d a(x, y, 1.0);
            normal += a * a.t();
            right += a * (1.0 / z);
            ++n;
        }
    }
    if (n < kMinPoints) return std::nullopt;
    cv::Vec3d plane;
    if (!cv::solve(normal, right, plane, cv::DECOMP_CHOLESKY)) return std::nullopt;
    return plane;
}

// The largest part, holes filled and opened against single pixels, of the pixels whose depth lies
// within bandMm of the surface whose inverse depth is `plane` (a x + b y + c).
cv::Mat partWithinBand(const cv::Mat& points, const cv::Vec3d& plane, double bandMm) {
    cv::Mat band = cv::Mat::zeros(points.size(), CV_8U);
    for (int y = 0; y < points.rows; ++y) {
        const auto* row = points.ptr<cv::Vec3f>(y);
        auto* out = band.ptr<std::uint8_t>(y);
        for (int x = 0; x < points.cols; ++x) {
            const double inverse = plane[0] * x + plane[1] * y + plane[2];
            if (std::isnan(row[x][2]) || !(inverse > 0)) continue;
            if (std::abs(row[x][2] - 1.0 / inverse) < bandMm) out[x] = 255;
        }
    }
    const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_ELLIPSE, {7, 7});
    cv::morphologyEx(band, band, cv::MORPH_OPEN, kernel);
    return largestPartFilled(band);
}

}  // namespace

std::vector<cv::Point2d> loadRoiPolygon(const std::filesystem::path& path) {
    const std::string where = path.string();
    std::ifstream in(path);
    if (!in) {
        throw Error(kExitNoInput, where + ": cannot read the region of interest");
    }
    nlohmann::json json;
    try {
        json = nlohmann::json::parse(in);
    } catch (const nlohmann::json::exception& e) {
        throw Error(kExitDataErr, where + ": not valid JSON: " + e.what());
    }
    if (!json.is_object() || !json.contains("polygon") || !json["polygon"].is_array()) {
        throw Error(kExitDataErr, where + ": polygon: missing or not an array of [x, y] points");
    }
    std::vector<cv::Point2d> polygon;
    for (const auto& point : json["polygon"]) {
        if (!point.is_array() || point.size() != 2 || !point[0].is_number() || !point[1].is_number()) {
            throw Error(kExitDataErr, where + ": polygon: every point must be [x, y] numbers");
        }
        polygon.emplace_back(point[0].get<double>(), point[1].get<double>());
    }
    if (polygon.size() < 3) {
        throw Error(kExitDataErr, where + ": polygon: needs at least 3 points");
    }
    return polygon;
}

std::vector<cv::Point2d> polygonFromFlat(const std::vector<double>& flat) {
    if (flat.size() % 2 != 0 || flat.size() < 6) {
        throw InvalidInput("region polygon: needs x, y pairs for at least 3 points");
    }
    std::vector<cv::Point2d> polygon;
    for (std::size_t i = 0; i < flat.size(); i += 2) polygon.emplace_back(flat[i], flat[i + 1]);
    return polygon;
}

cv::Mat roiMaskFromPolygon(const std::vector<cv::Point2d>& polygon, const calib::StereoCalibration& c) {
    std::vector<cv::Point2d> rectified;
    cv::undistortPoints(polygon, rectified, c.M1, c.D1, c.R1, c.P1);
    std::vector<cv::Point> vertices;
    for (const auto& p : rectified) vertices.emplace_back(static_cast<int>(std::lround(p.x)), static_cast<int>(std::lround(p.y)));
    cv::Mat mask = cv::Mat::zeros(c.imageSize, CV_8U);
    cv::fillPoly(mask, std::vector<std::vector<cv::Point>>{vertices}, cv::Scalar(255));
    return mask;
}

cv::Mat segmentRoi(const cv::Mat& points, double depthBandMm) {
    CV_Assert(points.type() == CV_32FC3);
    // The dominant depth: the histogram's peak in 10 mm bins.
    std::vector<int> histogram(1000, 0);
    for (int y = 0; y < points.rows; ++y) {
        const auto* row = points.ptr<cv::Vec3f>(y);
        for (int x = 0; x < points.cols; ++x) {
            const float z = row[x][2];
            if (!std::isnan(z) && z > 0 && z < 10000) ++histogram[static_cast<std::size_t>(z / 10)];
        }
    }
    const auto peak = std::max_element(histogram.begin(), histogram.end());
    if (*peak == 0) return cv::Mat::zeros(points.size(), CV_8U);
    const double dominantMm = (static_cast<double>(peak - histogram.begin()) + 0.5) * 10.0;
    cv::Mat region = partWithinBand(points, cv::Vec3d(0, 0, 1.0 / dominantMm), depthBandMm);
    // A blade turned out of the view (pitched, or swung about the tower) spans more depth than the
    // band from root to tip: a blade swung 13° lost its tip to the band about one depth, and the
    // tip's surface, left in the ring around the region, hid the bead beside it. The object's
    // surface is the band's centre instead, twice: the first part is most of it.
    for (int pass = 0; pass < 2; ++pass) {
        const std::optional<cv::Vec3d> surface = inverseDepthPlane(points, region);
        if (!surface) break;
        region = partWithinBand(points, *surface, depthBandMm);
    }
    return region;
}

cv::Mat segmentObject(const cv::Mat& points, const cv::Mat& grey, double depthBandMm, double minTextureGrey,
                      double minContrastGrey) {
    CV_Assert(grey.type() == CV_32FC1 && grey.size() == points.size());
    const cv::Mat atDepth = segmentRoi(points, depthBandMm);
    if (cv::countNonZero(atDepth) == 0) return atDepth;
    // The view as the outline: its pictured pixels, less a border for the ring outside it that
    // says what lies around (drawn_outline.cpp looks 6 px out).
    constexpr int kBorderPx = 16;
    cv::Mat view;
    cv::erode(grey > 0.0f, view, cv::getStructuringElement(cv::MORPH_RECT, {2 * kBorderPx + 1, 2 * kBorderPx + 1}),
              {-1, -1}, 1, cv::BORDER_CONSTANT, cv::Scalar(0));  // the frame's edge is outside
    const DrawnOutline rough = objectInDrawnOutline(view, grey, minTextureGrey, minContrastGrey);
    if (rough.backgroundPercent <= 0) {
        // No sky around it. A region the depth band cut out of the surface the object lies on is
        // the view (a blade on a table seen at 20°, faint, read -95 % and `ok` over a band of the
        // table reaching under 60 % of the frame's edge): all of it, for the region gate to refuse.
        if (surfaceContinues(atDepth, points)) return cv::Mat(points.size(), CV_8U, cv::Scalar(255));
        return atDepth;
    }
    const cv::Mat near = largestPartFilled(atDepth & rough.object);
    // Its edge once more, from an outline drawn 20 px around it: the ring along the view's edge
    // holds the sky's light across the whole frame, and its spread widens how like the sky a
    // pixel must be to be taken for it, so the first pass stops short of the edge (on a rendered
    // blade 619 px of its outline's 49 664 left out, 189 added, and the leading edge's ice read
    // 2.5 % lower than inside the drawn outline); the sky beside the object alone sets it here
    // (254 and 263).
    constexpr int kRedrawPx = 20;
    cv::Mat drawn;
    cv::dilate(near, drawn, cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * kRedrawPx + 1, 2 * kRedrawPx + 1}));
    drawn &= view;
    const DrawnOutline object = objectInDrawnOutline(drawn, grey, minTextureGrey, minContrastGrey);
    if (object.backgroundPercent <= 0) return near;
    return largestPartFilled(atDepth & object.object);
}

double frameEdgeShare(const cv::Mat& mask) {
    CV_Assert(mask.type() == CV_8UC1);
    if (mask.rows < 2 || mask.cols < 2) return 0.0;
    const int top = cv::countNonZero(mask.row(0)), bottom = cv::countNonZero(mask.row(mask.rows - 1));
    const int left = cv::countNonZero(mask(cv::Range(1, mask.rows - 1), cv::Range(0, 1)));
    const int right = cv::countNonZero(mask(cv::Range(1, mask.rows - 1), cv::Range(mask.cols - 1, mask.cols)));
    const double edge = 2.0 * mask.cols + 2.0 * (mask.rows - 2);
    return (top + bottom + left + right) / edge;
}

}  // namespace icewatch::volume
