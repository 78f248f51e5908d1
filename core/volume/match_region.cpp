// Where the captures after the baseline are matched (match_region.hpp).
//
// The blade fills a part of the frame and, between two captures, moves by millimetres: its
// disparities stay within a few pixels of where the baseline found them. So every later capture is
// rectified and matched only in the baseline region's bounding box, widened by
//   - the matcher's reach (its windows read that far, so the crop's edge changes nothing inside),
//   - the largest image motion the registration accepts (max_registration_mm at the region's
//     nearest depth), and
//   - the texture trackers' reach (patch radius and search), which read around the outline, or
//     the ring where ice standing out of the outline is looked for, the wider,
// and only in the band of disparities the baseline found in the region (robust percentiles),
// widened on the near side by the thickest ice it must see (max_ice_thickness_mm) and on both
// sides by that motion, converted through the calibration's Q exactly rather than by the
// first-order f·B/Z² (the same to well under a pixel here). Time and memory then follow the
// region and the band, not the frame and the full search.
#include "core/volume/match_region.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "core/common/error.hpp"
#include "core/volume/beyond_outline.hpp"

namespace icewatch::volume {

namespace {

// Percentiles of the band: a few stray disparities in the region (an outlier, a pixel of
// background inside a loose outline) must not widen the band for every later capture.
constexpr double kLowPercentile = 1.0;
constexpr double kHighPercentile = 99.0;
// Beyond the converted limits: one disparity so that the true match is not on the band's edge
// (reported invalid), one for the sub-pixel fit's neighbour and the percentiles' own spread.
constexpr int kBandSlack = 2;

// Depth of disparity d and disparity of depth z through Q (Z = Q23 / (Q32·d + Q33)).
double depthOf(const cv::Matx44d& q, double d) { return q(2, 3) / (q(3, 2) * d + q(3, 3)); }
double disparityOf(const cv::Matx44d& q, double z) { return (q(2, 3) / z - q(3, 3)) / q(3, 2); }

double percentile(std::vector<float>& values, double percent) {
    const auto k = static_cast<std::ptrdiff_t>(std::lround(percent / 100.0 * (values.size() - 1)));
    std::nth_element(values.begin(), values.begin() + k, values.end());
    return values[static_cast<std::size_t>(k)];
}

}  // namespace

int matcherReachPx(stereo::Method method, const stereo::Parameters& p) {
    if (method == stereo::Method::Sgbm) return p.sgbmBlockSize / 2 + 1 + p.subpixelWindowRadius;
    // Aggregation along the cross arms, then region voting over the same arms; the 9x9 Census
    // window (the paper's wider one) and the sub-pixel window.
    constexpr int kCensusRadius = 4;
    return 2 * std::max(p.crossL1, p.crossL2) + kCensusRadius + p.subpixelWindowRadius;
}

namespace {

// The region from a disparity map: band from its percentiles in the region, the near side widened
// by iceMm, both sides by bandMotionMm and slackPx; box from the region's bounds and the margins.
MatchRegion regionFrom(const cv::Mat& disparity, const cv::Mat& roi, const cv::Matx44d& q, double focalPx,
                       const Parameters& p, int reachPx, double iceMm, double bandMotionMm, int slackPx) {
    CV_Assert(disparity.type() == CV_32FC1 && roi.type() == CV_8UC1 && disparity.size() == roi.size());
    std::vector<float> inside;
    for (int y = 0; y < roi.rows; ++y) {
        const auto* m = roi.ptr<std::uint8_t>(y);
        const auto* d = disparity.ptr<float>(y);
        for (int x = 0; x < roi.cols; ++x)
            if (m[x] && d[x] > 0) inside.push_back(d[x]);
    }
    if (inside.empty()) throw InvalidInput("volume: the baseline's region holds no valid disparity");
    const double low = percentile(inside, kLowPercentile), high = percentile(inside, kHighPercentile);
    const double zNear = depthOf(q, high), zFar = depthOf(q, low);
    if (!(zNear > 0) || !(zFar > 0)) throw InvalidInput("volume: the baseline's region lies at no positive depth");

    MatchRegion region;
    // The nearest the ice and the motion can bring the surface, and the farthest the motion can take it.
    const double nearest = std::max(1.0, zNear - iceMm - bandMotionMm);
    const double farthest = zFar + bandMotionMm;
    const int slack = kBandSlack + slackPx;
    region.band.max = std::min(p.maxDisparity, static_cast<int>(std::ceil(disparityOf(q, nearest))) + slack + 1);
    region.band.min = std::max(0, static_cast<int>(std::floor(disparityOf(q, farthest))) - slack);
    region.band.min = std::max(0, std::min(region.band.min, region.band.max - stereo::kMinDisparityBand));

    const int motionPx = static_cast<int>(std::ceil(p.maxRegistrationMm * focalPx / zNear));
    region.reachPx = reachPx;
    // Beyond the outline: the trackers' patches, and the ring where ice standing out of it is looked for.
    const int aroundPx = std::max(p.trackRadiusPx + p.trackSearchPx, outlineGrowthPx(p, focalPx, zNear));
    region.marginPx = reachPx + motionPx + aroundPx;
    const cv::Rect bounds = cv::boundingRect(roi);
    region.regionBox = bounds;
    const cv::Rect widened(bounds.x - region.marginPx, bounds.y - region.marginPx, bounds.width + 2 * region.marginPx,
                           bounds.height + 2 * region.marginPx);
    region.box = widened & cv::Rect(0, 0, roi.cols, roi.rows);
    return region;
}

}  // namespace

MatchRegion matchRegionFromBaseline(const cv::Mat& disparity, const cv::Mat& roi, const cv::Matx44d& q,
                                    double focalPx, const Parameters& p, int reachPx) {
    return regionFrom(disparity, roi, q, focalPx, p, reachPx, p.maxIceThicknessMm, p.maxRegistrationMm, 0);
}

MatchRegion baselineRegionFromCoarse(const cv::Mat& coarseDisparity, const cv::Mat& roi, const cv::Matx44d& q,
                                     double focalPx, const Parameters& p, int reachPx, int coarseFactor) {
    // A coarse disparity is good to about one coarse pixel: the band allows two either side.
    return regionFrom(coarseDisparity, roi, q, focalPx, p, reachPx, 0.0, 0.0, 2 * coarseFactor);
}

cv::Rect coarseWindow(const cv::Mat& roi, int maxDisparity, int reachPx, int coarseFactor) {
    const cv::Rect bounds = cv::boundingRect(roi);
    const int r = reachPx * coarseFactor;  // the coarse matcher's windows reach this far in full pixels
    const cv::Rect widened(bounds.x - r - maxDisparity, bounds.y - r, bounds.width + 2 * r + maxDisparity,
                           bounds.height + 2 * r);
    cv::Rect window = widened & cv::Rect(0, 0, roi.cols, roi.rows);
    // Whole coarse pixels.
    window.width -= window.width % coarseFactor;
    window.height -= window.height % coarseFactor;
    return window;
}

cv::Rect matcherWindow(const MatchRegion& region, cv::Size imageSize) {
    const int left = std::max(0, region.box.x - region.band.max);
    return cv::Rect(left, region.box.y, region.box.x + region.box.width - left, region.box.height) &
           cv::Rect(cv::Point(0, 0), imageSize);
}

double maskedCorrelation(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask) {
    CV_Assert(a.type() == CV_32FC1 && b.type() == CV_32FC1 && mask.type() == CV_8UC1 && a.size() == b.size() &&
              a.size() == mask.size());
    cv::Scalar meanA, sigmaA, meanB, sigmaB;
    cv::meanStdDev(a, meanA, sigmaA, mask);
    cv::meanStdDev(b, meanB, sigmaB, mask);
    const int n = cv::countNonZero(mask);
    if (n == 0 || sigmaA[0] <= 1e-9 || sigmaB[0] <= 1e-9) return 0.0;
    cv::Mat da, db;
    cv::subtract(a, meanA, da, mask, CV_64F);
    cv::subtract(b, meanB, db, mask, CV_64F);
    return da.dot(db) / (n * sigmaA[0] * sigmaB[0]);
}

std::optional<std::string> regionProblem(const MatchRegion& region, cv::Size imageSize, cv::Point2d shiftPx) {
    if (region.empty()) return std::nullopt;
    // Where the matched box's edge was cut by the crop (not by the image's own border), the
    // matcher's reach is lost: the moved region must stay that far inside.
    const cv::Rect image(cv::Point(0, 0), imageSize);
    const int r = region.reachPx;
    const int left = region.box.x > 0 ? region.box.x + r : 0;
    const int top = region.box.y > 0 ? region.box.y + r : 0;
    const int right = region.box.br().x < image.width ? region.box.br().x - r : image.width;
    const int bottom = region.box.br().y < image.height ? region.box.br().y - r : image.height;
    const double x0 = region.regionBox.x + shiftPx.x, y0 = region.regionBox.y + shiftPx.y;
    const double x1 = region.regionBox.br().x + shiftPx.x, y1 = region.regionBox.br().y + shiftPx.y;
    if (x0 >= left && y0 >= top && x1 <= right && y1 <= bottom) return std::nullopt;
    std::ostringstream why;
    why.precision(3);
    why << "the object moved " << std::hypot(shiftPx.x, shiftPx.y) << " px (" << shiftPx.x << ", " << shiftPx.y
        << ") out of the region matched around the baseline's (margin " << region.marginPx - r
        << " px); take a new baseline if it stays there";
    return why.str();
}

}  // namespace icewatch::volume
