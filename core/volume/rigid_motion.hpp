#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "core/volume/registration.hpp"

namespace icewatch::volume {

// One point seen in both captures, with the covariance of its measured displacement.
struct PointPair {
    cv::Vec3d current;   // mm
    cv::Vec3d baseline;  // mm
    cv::Matx33d covarianceMm2 = cv::Matx33d::eye();
};

struct RigidMotionOptions {
    int ransacIterations = 300;
    std::uint32_t seed = 1;        // RANSAC draws (fixed: the result does not depend on timing)
    double inlierChi2 = 16.27;     // squared Mahalanobis distance of an inlier (χ² with 3 dof at 99.9 %)
    int refineIterations = 10;
    // Neighbouring pairs share pixels (overlapping patches): their errors are correlated and the
    // covariance of the fit is this many times what independent pairs would give.
    double correlationFactor = 1.0;
    // Ice only adds material towards the camera: a pair that rose along this axis (the object's
    // normal, towards the camera) by more than riseSigmas of its own σ along it is left out, while
    // one that fell stays an inlier up to the symmetric χ² bound. Thin clear ice that kept its look
    // would otherwise be averaged into the motion and read as none. Zero axis: symmetric.
    cv::Vec3d riseAxis{0, 0, 0};
    double riseSigmas = 2.5;
    // Every pair's covariance times this (fitRigidMotion sets it from the data: the trackers'
    // own covariances may be too optimistic, and a fixed χ² bound would then reject good pairs).
    double covarianceScale = 1.0;
    // The consensus in its plain form: every RANSAC draw counted over every pair, none stopped
    // once it cannot win (fitRigidMotion). The same fit; tests hold the two together.
    bool countEveryDraw = false;
};

struct RigidMotion {
    bool ok = false;
    RigidTransform transform;  // current -> baseline
    // Of the left perturbation (rotation vector in rad, translation in mm): T' = exp(ω)·T + δt.
    cv::Matx66d covariance = cv::Matx66d::zeros();
    std::vector<std::uint8_t> inlier;  // per pair
    int inliers = 0;
    double chi2PerDof = 0;  // of the inliers at the end, after covarianceScale: about 1
    double covarianceScale = 1.0;  // what the pairs' covariances were scaled by (their honesty)
};

// The rigid transform that maps `from` onto `to` in the least-squares sense (Umeyama, no scale).
// Needs at least 3 non-collinear pairs; throws InvalidInput otherwise.
RigidTransform fitRigid(const std::vector<cv::Vec3d>& from, const std::vector<cv::Vec3d>& to);

// Robust rigid fit of current onto baseline points, each pair weighted by its own covariance
// (depth is far less certain than the position across the view): RANSAC on three pairs for the
// consensus, then Gauss-Newton on the Mahalanobis distances of the inliers, re-selected at every
// step. The pairs' covariances are first scaled so that the lower quartile of every pair's χ² under
// the consensus is that of a χ² with 3 degrees of freedom (1.213; the upper part may be ice or
// mismatches), never by less than 1: they are not made more optimistic. The fit's
// covariance is then scaled by the inliers' χ² per degree of freedom when that exceeds 1 and by
// the correlation factor. Not ok with fewer than `minPairs` inliers.
RigidMotion fitRigidMotion(const std::vector<PointPair>& pairs, const RigidMotionOptions& options = {},
                           int minPairs = 6);

// A pair's covariance as the fit weighs it: its own times covarianceScale.
cv::Matx33d pairCovariance(const PointPair& pair, const RigidMotionOptions& options);

// Squared Mahalanobis distance of one pair under a transform.
double pairChi2(const PointPair& pair, const RigidTransform& transform, const RigidMotionOptions& options);

// Whether a pair agrees with a transform: within the χ² bound and not risen beyond riseSigmas.
bool pairAgrees(const PointPair& pair, const RigidTransform& transform, const RigidMotionOptions& options);

// The 1-σ change of a quantity whose gradient with respect to the left perturbation is `gradient`.
double propagate(const cv::Vec6d& gradient, const cv::Matx66d& covariance);

}  // namespace icewatch::volume
