#pragma once

#include <vector>

#include <opencv2/core.hpp>

namespace icewatch::volume {

struct PlaneFrame;

struct RigidTransform {
    cv::Matx33d rotation = cv::Matx33d::eye();
    cv::Vec3d translation{0, 0, 0};
    cv::Vec3d apply(const cv::Vec3d& p) const { return rotation * p + translation; }
};

struct RegistrationOptions {
    int iterations = 50;
    double convergenceMm = 0.02;
    double trimSigma = 3.0;
    double settledMm = 0.2;  // after all iterations, a last update below this still counts as converged
    // When set, only the motions out of the plane with this normal through this centre are
    // estimated (tilts about the in-plane axes, translation along the normal); the in-plane ones
    // stay as `initial` has them (e.g. from the texture, which pins them far better than shape).
    bool outOfPlaneOnly = false;
    cv::Vec3d planeNormal{0, 0, 1};
    cv::Vec3d planeCentre{0, 0, 0};
};

struct RegistrationResult {
    RigidTransform transform;  // current -> baseline
    bool converged = false;
    int iterations = 0;
    int inliers = 0;
    double sigmaMm = 0;  // robust σ of the point-to-plane residuals at the end
    // Covariance of the last linearised update (rotation vector in rad, translation in mm),
    // assuming independent residuals; scale it by the correlation of neighbouring points.
    cv::Matx66d covariance = cv::Matx66d::zeros();
    std::vector<double> residualsMm;  // per current point, NaN where it found no partner
};

// Normals of an organised cloud (CV_32FC3, NaN = none) from central differences `radius`
// pixels apart, oriented towards the camera. CV_32FC3, NaN where they cannot be formed.
cv::Mat organizedNormals(const cv::Mat& points, int radius);

// Rigid point-to-plane ICP of scattered current points onto an organised baseline cloud.
// Partners by projective association: a transformed point is projected with the baseline's
// left rectified camera `projection` (P1, 3×4) and meets the baseline point at that pixel, if
// `baselineMask` allows it. The loss is robust: Tukey's biweight on the residual with a scale from
// the median absolute deviation, and residuals beyond trimSigma scales are left out. `use` (one
// flag per current point, may be empty) restricts the points that drive the fit, e.g. to the
// parts of the surface that did not change; residuals are returned for every point. With
// options.iterations = 0 it only evaluates the residuals at `initial`.
RegistrationResult registerPointToPlane(const cv::Mat& baselinePoints, const cv::Mat& baselineNormals,
                                        const cv::Mat& baselineMask, const cv::Matx34d& projection,
                                        const std::vector<cv::Vec3d>& currentPoints,
                                        const std::vector<std::uint8_t>& use, const RigidTransform& initial,
                                        const RegistrationOptions& options);

// How much of the object the points that fixed the registration span: each of the object's two
// in-plane axes is cut into ten bins over the region's extent, a bin counts when the support holds
// at least a third of the region's samples in it, and the smaller share of counted bins is
// returned. A tilt fitted on a patch at one end is extrapolated over the rest, its error growing
// with the distance: support over a seventh of a blade's span, as when ice hides the texture
// everywhere but at the root, turned a 97 609 mm³ blade into 680 000 mm³. A few scattered texture
// patches do not make a support either: the matcher's errors are correlated over centimetres.
// `samples`: current points, moved by `transform` into the baseline and put in `plane`;
// `support`: one flag per sample (empty: all). Percent, 0 with fewer than 2 samples.
double supportSpanPercent(const std::vector<cv::Vec3d>& samples, const std::vector<std::uint8_t>& support,
                          const RigidTransform& transform, const PlaneFrame& plane);

}  // namespace icewatch::volume
