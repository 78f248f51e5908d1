// Registration from the image texture. Point-to-plane ICP only sees shape: on a nearly extruded
// blade, a slide along the span or a turn about the surface normal changes almost no residual, so
// ICP wanders there and the ice drags it. The texture of the unchanged composite pins those
// directions: features tracked between the two left images and lifted to 3-D with each capture's
// own disparities give point pairs whose rigid fit is exact in the image plane (Lucas-Kanade is
// good to a few hundredths of a pixel) and coarse in depth, which ICP then refines.
#include "core/volume/texture_registration.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "core/common/error.hpp"

namespace icewatch::volume {

namespace {

// Bilinear 3-D point of an organised cloud at a sub-pixel position; false if a corner is missing.
bool samplePoint(const cv::Mat& points, const cv::Point2f& at, cv::Vec3d& out) {
    const int x = static_cast<int>(std::floor(at.x)), y = static_cast<int>(std::floor(at.y));
    if (x < 0 || y < 0 || x + 1 >= points.cols || y + 1 >= points.rows) return false;
    const double fx = at.x - x, fy = at.y - y;
    out = {0, 0, 0};
    for (int k = 0; k < 4; ++k) {
        const cv::Vec3f q = points.at<cv::Vec3f>(y + (k >> 1), x + (k & 1));
        if (std::isnan(q[2])) return false;
        const double w = ((k & 1) ? fx : 1 - fx) * ((k >> 1) ? fy : 1 - fy);
        out += w * cv::Vec3d(q[0], q[1], q[2]);
    }
    return true;
}

// The 3-D point at a sub-pixel position with its depth averaged over a (2r+1)² window: the ray is
// exact (the organised cloud's X/Z, Y/Z), the depth of one disparity is noisy and its noise would
// move the point sideways by as much as Z·tan(ray angle). False if the point cannot be formed.
bool liftSmoothed(const cv::Mat& points, const cv::Point2f& at, int radius, cv::Vec3d& out) {
    if (!samplePoint(points, at, out)) return false;
    const int cx = cvRound(at.x), cy = cvRound(at.y);
    double sum = 0;
    int count = 0;
    for (int y = std::max(0, cy - radius); y <= std::min(points.rows - 1, cy + radius); ++y)
        for (int x = std::max(0, cx - radius); x <= std::min(points.cols - 1, cx + radius); ++x) {
            const float z = points.at<cv::Vec3f>(y, x)[2];
            if (!std::isnan(z)) {
                sum += z;
                ++count;
            }
        }
    if (count < (2 * radius + 1) * (2 * radius + 1) / 2) return false;
    out *= (sum / count) / out[2];
    return true;
}

}  // namespace

RigidTransform fitRigid(const std::vector<cv::Vec3d>& from, const std::vector<cv::Vec3d>& to) {
    if (from.size() != to.size() || from.size() < 3) {
        throw InvalidInput("rigid fit: needs at least 3 point pairs");
    }
    Eigen::Matrix3Xd a(3, static_cast<Eigen::Index>(from.size())), b(3, static_cast<Eigen::Index>(to.size()));
    for (std::size_t i = 0; i < from.size(); ++i) {
        const auto c = static_cast<Eigen::Index>(i);
        a.col(c) << from[i][0], from[i][1], from[i][2];
        b.col(c) << to[i][0], to[i][1], to[i][2];
    }
    const Eigen::Matrix4d m = Eigen::umeyama(a, b, false);
    if (!m.allFinite()) throw InvalidInput("rigid fit: degenerate point pairs");
    RigidTransform t;
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) t.rotation(r, c) = m(r, c);
        t.translation[r] = m(r, 3);
    }
    return t;
}

TextureRegistrationResult registerByTexture(const cv::Mat& baselineLeft, const cv::Mat& baselinePoints,
                                            const cv::Mat& currentLeft, const cv::Mat& currentPoints,
                                            const cv::Mat& mask, const PlaneFrame& plane,
                                            const TextureRegistrationOptions& options) {
    if (baselineLeft.type() != CV_8U || currentLeft.type() != CV_8U || baselineLeft.size() != currentLeft.size() ||
        baselinePoints.type() != CV_32FC3 || currentPoints.type() != CV_32FC3 ||
        baselinePoints.size() != baselineLeft.size() || currentPoints.size() != currentLeft.size() ||
        mask.type() != CV_8U || mask.size() != currentLeft.size()) {
        throw InvalidInput("texture registration: grey images, clouds and mask must be organised alike");
    }
    TextureRegistrationResult result;
    std::vector<cv::Point2f> corners;
    // A low quality level: the composite's texture is weak, and Lucas-Kanade with the round-trip
    // check tells good tracks from bad better than the corner score does.
    cv::goodFeaturesToTrack(currentLeft, corners, options.maxFeatures, 1e-4, options.minFeatureDistancePx, mask, 7);
    if (corners.size() < 3) return result;
    std::vector<cv::Point2f> tracked, back;
    std::vector<std::uint8_t> status, statusBack;
    std::vector<float> error;
    const cv::Size window(options.trackWindowPx, options.trackWindowPx);
    const cv::TermCriteria stop(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 40, 1e-3);
    cv::calcOpticalFlowPyrLK(currentLeft, baselineLeft, corners, tracked, status, error, window, 3, stop);
    cv::calcOpticalFlowPyrLK(baselineLeft, currentLeft, tracked, back, statusBack, error, window, 3, stop);
    std::vector<cv::Vec3d> from, to;
    std::vector<cv::Point2f> fromPixel;
    for (std::size_t i = 0; i < corners.size(); ++i) {
        if (!status[i] || !statusBack[i]) continue;
        const cv::Point2f d = back[i] - corners[i];
        if (std::hypot(d.x, d.y) > options.maxRoundTripPx) continue;
        cv::Vec3d p, q;
        if (!liftSmoothed(currentPoints, corners[i], options.depthRadiusPx, p) ||
            !liftSmoothed(baselinePoints, tracked[i], options.depthRadiusPx, q)) {
            continue;
        }
        from.push_back(p);
        to.push_back(q);
        fromPixel.push_back(corners[i]);
    }
    result.tracked = static_cast<int>(from.size());
    if (from.size() < 6) return result;

    // In the object's plane only: lifted points carry the depth noise of one disparity (mm),
    // which would tilt a 3-D fit of points spread along a narrow blade; the plane coordinates of
    // many matches average it out, and the shape fixes the out-of-plane motion afterwards.
    std::vector<cv::Vec2d> a, b;
    for (std::size_t i = 0; i < from.size(); ++i) {
        const cv::Point3d pa = plane.toPlane(from[i]), pb = plane.toPlane(to[i]);
        a.emplace_back(pa.x, pa.y);
        b.emplace_back(pb.x, pb.y);
    }
    std::mt19937 random(options.seed);
    std::uniform_int_distribution<std::size_t> pick(0, a.size() - 1);
    // Least-squares 2-D rigid fit in closed form: the turn from the centred cross and dot sums.
    auto fit2d = [&](const std::vector<std::size_t>& which) {
        cv::Vec2d ca(0, 0), cb(0, 0);
        for (std::size_t k : which) {
            ca += a[k];
            cb += b[k];
        }
        ca /= static_cast<double>(which.size());
        cb /= static_cast<double>(which.size());
        double cross = 0, dot = 0;
        for (std::size_t k : which) {
            const cv::Vec2d pa = a[k] - ca, pb = b[k] - cb;
            cross += pa[0] * pb[1] - pa[1] * pb[0];
            dot += pa[0] * pb[0] + pa[1] * pb[1];
        }
        const double angle = std::atan2(cross, dot), c = std::cos(angle), s = std::sin(angle);
        Eigen::Matrix3d m = Eigen::Matrix3d::Identity();
        m(0, 0) = c;
        m(0, 1) = -s;
        m(1, 0) = s;
        m(1, 1) = c;
        m(0, 2) = cb[0] - (c * ca[0] - s * ca[1]);
        m(1, 2) = cb[1] - (s * ca[0] + c * ca[1]);
        return m;
    };
    auto distance2 = [&](const Eigen::Matrix3d& m, std::size_t i) {
        const double x = m(0, 0) * a[i][0] + m(0, 1) * a[i][1] + m(0, 2) - b[i][0];
        const double y = m(1, 0) * a[i][0] + m(1, 1) * a[i][1] + m(1, 2) - b[i][1];
        return x * x + y * y;
    };
    auto inliersOf = [&](const Eigen::Matrix3d& m, std::vector<std::size_t>& out) {
        out.clear();
        for (std::size_t i = 0; i < a.size(); ++i) {
            if (std::sqrt(distance2(m, i)) < options.inlierMm) out.push_back(i);
        }
    };
    std::vector<std::size_t> best, candidate;
    for (int iteration = 0; iteration < options.ransacIterations; ++iteration) {
        const std::size_t i = pick(random), j = pick(random);
        if (cv::norm(a[i] - a[j]) < 20.0) continue;  // too close to fix a turn
        const Eigen::Matrix3d m = fit2d({i, j});
        if (!m.allFinite()) continue;
        inliersOf(m, candidate);
        if (candidate.size() > best.size()) best.swap(candidate);
    }
    if (best.size() < 6) return result;
    Eigen::Matrix3d m = Eigen::Matrix3d::Identity();
    for (int pass = 0; pass < 2; ++pass) {  // refit on the inliers; the set settles as the model improves
        m = fit2d(best);
        inliersOf(m, best);
        if (best.size() < 6) return result;
    }
    double sum = 0;
    for (std::size_t i : best) {
        sum += distance2(m, i);
    }
    // Back to the camera frame: a turn about the normal through the plane's origin and an
    // in-plane translation.
    const cv::Matx33d axes(plane.axisU[0], plane.axisV[0], plane.normal[0], plane.axisU[1], plane.axisV[1],
                           plane.normal[1], plane.axisU[2], plane.axisV[2], plane.normal[2]);
    const cv::Matx33d inPlane(m(0, 0), m(0, 1), 0, m(1, 0), m(1, 1), 0, 0, 0, 1);
    result.transform.rotation = axes * inPlane * axes.t();
    result.transform.translation =
        plane.origin - result.transform.rotation * plane.origin + axes * cv::Vec3d(m(0, 2), m(1, 2), 0);
    result.inliers = static_cast<int>(best.size());
    for (std::size_t i : best) result.inlierPixels.push_back(fromPixel[i]);
    result.rmsMm = std::sqrt(sum / static_cast<double>(best.size()));
    result.ok = true;
    return result;
}

}  // namespace icewatch::volume
