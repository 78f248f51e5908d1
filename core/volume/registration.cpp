// Registration of the current capture onto the baseline. A parked blade is never where it was:
// without this, a movement of 1 mm along the view axis is 1 mm of "ice" over the whole blade.
// Point-to-plane ICP converges in a few iterations on smooth surfaces; projective association
// costs O(1) per point because the baseline cloud is organised on the rectified pixel lattice.
#include "core/volume/registration.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Dense>

#include "core/common/error.hpp"
#include "core/volume/height_grid.hpp"

namespace icewatch::volume {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Eigenvalues below this fraction of the largest mark a direction the surface does not constrain.
constexpr double kDegenerateRatio = 1e-2;

double median(std::vector<double> values) {
    if (values.empty()) return 0.0;
    const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
    std::nth_element(values.begin(), mid, values.end());
    return *mid;
}

cv::Matx33d rotationFromVector(const Eigen::Vector3d& w) {
    const double angle = w.norm();
    if (angle < 1e-15) return cv::Matx33d::eye();
    const Eigen::Matrix3d r = Eigen::AngleAxisd(angle, w / angle).toRotationMatrix();
    return cv::Matx33d(r(0, 0), r(0, 1), r(0, 2), r(1, 0), r(1, 1), r(1, 2), r(2, 0), r(2, 1), r(2, 2));
}

}  // namespace

cv::Mat organizedNormals(const cv::Mat& points, int radius) {
    CV_Assert(points.type() == CV_32FC3 && radius >= 1);
    cv::Mat normals(points.size(), CV_32FC3, cv::Scalar::all(std::numeric_limits<float>::quiet_NaN()));
    for (int y = radius; y + radius < points.rows; ++y) {
        for (int x = radius; x + radius < points.cols; ++x) {
            const cv::Vec3f l = points.at<cv::Vec3f>(y, x - radius), r = points.at<cv::Vec3f>(y, x + radius);
            const cv::Vec3f u = points.at<cv::Vec3f>(y - radius, x), d = points.at<cv::Vec3f>(y + radius, x);
            if (std::isnan(l[2]) || std::isnan(r[2]) || std::isnan(u[2]) || std::isnan(d[2])) continue;
            cv::Vec3f n = (r - l).cross(d - u);
            const float len = static_cast<float>(cv::norm(n));
            if (len <= 0) continue;
            n /= len;
            normals.at<cv::Vec3f>(y, x) = n[2] > 0 ? -n : n;
        }
    }
    return normals;
}

RegistrationResult registerPointToPlane(const cv::Mat& baselinePoints, const cv::Mat& baselineNormals,
                                        const cv::Mat& baselineMask, const cv::Matx34d& projection,
                                        const std::vector<cv::Vec3d>& currentPoints,
                                        const std::vector<std::uint8_t>& use, const RigidTransform& initial,
                                        const RegistrationOptions& options) {
    if (baselinePoints.type() != CV_32FC3 || baselineNormals.type() != CV_32FC3 || baselineMask.type() != CV_8U ||
        baselineNormals.size() != baselinePoints.size() || baselineMask.size() != baselinePoints.size()) {
        throw InvalidInput("registration: baseline points, normals and mask must be organised alike");
    }
    if (!use.empty() && use.size() != currentPoints.size()) {
        throw InvalidInput("registration: one use flag per current point expected");
    }
    RegistrationResult result;
    result.transform = initial;
    result.residualsMm.assign(currentPoints.size(), kNaN);
    const int width = baselinePoints.cols, height = baselinePoints.rows;
    // The point-to-plane residual of p against the baseline point it projects onto; NaN if none.
    auto associate = [&](const cv::Vec3d& p, cv::Vec3d& normal) {
        if (p[2] <= 0) return kNaN;
        const double u = (projection(0, 0) * p[0] + projection(0, 1) * p[1] + projection(0, 2) * p[2] +
                          projection(0, 3)) / p[2];
        const double v = (projection(1, 0) * p[0] + projection(1, 1) * p[1] + projection(1, 2) * p[2] +
                          projection(1, 3)) / p[2];
        // Bilinear between the four baseline pixels around the projection: a partner that moves
        // continuously with the transform lets the iteration settle instead of hopping pixels.
        const int x = static_cast<int>(std::floor(u)), y = static_cast<int>(std::floor(v));
        if (x < 0 || y < 0 || x + 1 >= width || y + 1 >= height) return kNaN;
        const double fx = u - x, fy = v - y;
        cv::Vec3d q(0, 0, 0), n(0, 0, 0);
        for (int k = 0; k < 4; ++k) {
            const int xx = x + (k & 1), yy = y + (k >> 1);
            const cv::Vec3f qk = baselinePoints.at<cv::Vec3f>(yy, xx);
            const cv::Vec3f nk = baselineNormals.at<cv::Vec3f>(yy, xx);
            if (!baselineMask.at<std::uint8_t>(yy, xx) || std::isnan(qk[2]) || std::isnan(nk[2])) return kNaN;
            const double w = ((k & 1) ? fx : 1 - fx) * ((k >> 1) ? fy : 1 - fy);
            q += w * cv::Vec3d(qk[0], qk[1], qk[2]);
            n += w * cv::Vec3d(nk[0], nk[1], nk[2]);
        }
        normal = cv::normalize(n);
        return normal.dot(p - q);
    };

    struct Pair {
        cv::Vec3d p;  // transformed current point
        cv::Vec3d n;
        double r;
    };
    std::vector<Pair> pairs;
    pairs.reserve(currentPoints.size());
    std::vector<double> absResiduals;
    double scale = std::numeric_limits<double>::infinity();
    Eigen::Matrix<double, 6, 6> lastInverse = Eigen::Matrix<double, 6, 6>::Zero();

    for (int iteration = 0; iteration < options.iterations; ++iteration) {
        pairs.clear();
        for (std::size_t i = 0; i < currentPoints.size(); ++i) {
            const cv::Vec3d p = result.transform.apply(currentPoints[i]);
            cv::Vec3d n;
            result.residualsMm[i] = associate(p, n);
            if (!std::isnan(result.residualsMm[i]) && (use.empty() || use[i])) {
                pairs.push_back({p, n, result.residualsMm[i]});
            }
        }
        if (pairs.size() < 6) {
            result.converged = false;
            result.iterations = iteration;
            return result;
        }
        absResiduals.clear();
        for (const Pair& pr : pairs) absResiduals.push_back(std::abs(pr.r));
        const double robustSigma = std::max(1e-6, 1.4826 * median(absResiduals));
        scale = robustSigma;
        const double cutoff = options.trimSigma * robustSigma;
        const double tukey = 4.685 * robustSigma;

        Eigen::Matrix<double, 6, 6> a = Eigen::Matrix<double, 6, 6>::Zero();
        Eigen::Matrix<double, 6, 1> b = Eigen::Matrix<double, 6, 1>::Zero();
        int inliers = 0;
        double weightSum = 0;
        for (const Pair& pr : pairs) {
            if (std::abs(pr.r) > cutoff) continue;
            const double t = pr.r / tukey;
            const double w = (1 - t * t) * (1 - t * t);
            const cv::Vec3d c = pr.p.cross(pr.n);
            Eigen::Matrix<double, 6, 1> j;
            j << c[0], c[1], c[2], pr.n[0], pr.n[1], pr.n[2];
            a += w * j * j.transpose();
            b += w * pr.r * j;
            weightSum += w;
            ++inliers;
        }
        if (inliers < 6) {
            result.converged = false;
            result.iterations = iteration;
            return result;
        }
        Eigen::Matrix<double, 6, 1> delta;
        if (options.outOfPlaneOnly) {
            // Tilts about the in-plane axes through the centre, and the normal translation.
            const cv::Vec3d n = cv::normalize(options.planeNormal);
            const cv::Vec3d u = cv::normalize(std::abs(n[0]) < 0.9 ? n.cross(cv::Vec3d(1, 0, 0)) : n.cross(cv::Vec3d(0, 1, 0)));
            const cv::Vec3d v = n.cross(u);
            Eigen::Matrix<double, 6, 3> basis;
            const cv::Vec3d tu = -u.cross(options.planeCentre), tv = -v.cross(options.planeCentre);
            basis << u[0], v[0], 0, u[1], v[1], 0, u[2], v[2], 0, tu[0], tv[0], n[0], tu[1], tv[1], n[1], tu[2], tv[2],
                n[2];
            const Eigen::Matrix3d reduced = basis.transpose() * a * basis;
            const Eigen::Matrix3d reducedInverse = reduced.inverse();
            if (!reducedInverse.allFinite()) {
                result.converged = false;
                result.iterations = iteration;
                return result;
            }
            delta = -basis * (reducedInverse * (basis.transpose() * b));
            lastInverse = basis * reducedInverse * basis.transpose() *
                          (weightSum > 0 ? static_cast<double>(inliers) / weightSum : 1.0);
        } else {
            // Directions the surface does not constrain (sliding over a plate, turning about its
            // normal, sliding along an extruded blade) are left out of the update: their eigenvalues
            // are noise. Rotations are scaled by the depth first so all six are in millimetres.
            const double depthScale = std::max(1.0, std::abs(pairs.front().p[2]));
            Eigen::Matrix<double, 6, 1> unitScale;
            unitScale << 1.0 / depthScale, 1.0 / depthScale, 1.0 / depthScale, 1.0, 1.0, 1.0;
            const Eigen::Matrix<double, 6, 6> scaledA = unitScale.asDiagonal() * a * unitScale.asDiagonal();
            const Eigen::Matrix<double, 6, 1> scaledB = unitScale.asDiagonal() * b;
            const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eigen(scaledA);
            const double largest = eigen.eigenvalues().maxCoeff();
            Eigen::Matrix<double, 6, 1> scaledDelta = Eigen::Matrix<double, 6, 1>::Zero();
            Eigen::Matrix<double, 6, 6> scaledInverse = Eigen::Matrix<double, 6, 6>::Zero();
            for (int e = 0; e < 6; ++e) {
                const double lambda = eigen.eigenvalues()(e);
                if (lambda <= kDegenerateRatio * largest) continue;
                const Eigen::Matrix<double, 6, 1> v = eigen.eigenvectors().col(e);
                scaledDelta -= v * (v.dot(scaledB) / lambda);
                scaledInverse += v * v.transpose() / lambda;
            }
            delta = unitScale.asDiagonal() * scaledDelta;
            lastInverse = unitScale.asDiagonal() * scaledInverse * unitScale.asDiagonal() *
                          (weightSum > 0 ? static_cast<double>(inliers) / weightSum : 1.0);
        }
        const cv::Matx33d dr = rotationFromVector(delta.head<3>());
        result.transform.rotation = dr * result.transform.rotation;
        result.transform.translation = dr * result.transform.translation + cv::Vec3d(delta(3), delta(4), delta(5));
        result.inliers = inliers;
        result.iterations = iteration + 1;
        // How far the update moved a point at the cloud's distance.
        const double depth = std::abs(pairs.front().p[2]);
        const double step = delta.tail<3>().norm() + delta.head<3>().norm() * depth;
        if (step < options.convergenceMm) {
            result.converged = true;
            break;
        }
        // Out of iterations: a fit that still moves by a little only jitters in a direction the
        // surface barely constrains, which changes no thickness; a large last step is a real failure.
        if (iteration + 1 == options.iterations) result.converged = step < options.settledMm;
    }
    result.sigmaMm = scale;
    const Eigen::Matrix<double, 6, 6> covariance = scale * scale * lastInverse;
    for (int r = 0; r < 6; ++r)
        for (int c = 0; c < 6; ++c) result.covariance(r, c) = covariance(r, c);
    // Residuals at the final transform for every point, for the caller's change detection.
    for (std::size_t i = 0; i < currentPoints.size(); ++i) {
        cv::Vec3d n;
        result.residualsMm[i] = associate(result.transform.apply(currentPoints[i]), n);
    }
    return result;
}

double supportSpanPercent(const std::vector<cv::Vec3d>& samples, const std::vector<std::uint8_t>& support,
                          const RigidTransform& transform, const PlaneFrame& plane) {
    constexpr int kBins = 10;
    std::vector<cv::Point2d> all;
    for (const cv::Vec3d& sample : samples) {
        const cv::Point3d local = plane.toPlane(transform.apply(sample));
        all.emplace_back(local.x, local.y);
    }
    if (all.size() < 2) return 0.0;
    double share = 1.0;
    for (int axis = 0; axis < 2; ++axis) {
        auto coordinate = [axis](const cv::Point2d& q) { return axis == 0 ? q.x : q.y; };
        double lo = coordinate(all.front()), hi = lo;
        for (const cv::Point2d& q : all) {
            lo = std::min(lo, coordinate(q));
            hi = std::max(hi, coordinate(q));
        }
        std::vector<int> region(kBins, 0), supported(kBins, 0);
        for (std::size_t i = 0; i < all.size(); ++i) {
            const int bin = std::clamp(static_cast<int>((coordinate(all[i]) - lo) / std::max(1e-9, hi - lo) * kBins), 0,
                                       kBins - 1);
            ++region[bin];
            if (support.empty() || support[i]) ++supported[bin];
        }
        int covered = 0, occupied = 0;
        for (int bin = 0; bin < kBins; ++bin) {
            if (region[bin] == 0) continue;
            ++occupied;
            if (3 * supported[bin] >= region[bin]) ++covered;
        }
        share = std::min(share, occupied > 0 ? static_cast<double>(covered) / occupied : 0.0);
    }
    return 100.0 * share;
}

}  // namespace icewatch::volume
