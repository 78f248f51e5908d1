// Robust, covariance-weighted rigid fit of point pairs (rigid_motion.hpp).
#include "core/volume/rigid_motion.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include <Eigen/Geometry>
#include <opencv2/calib3d.hpp>

#include "core/common/error.hpp"
#include "core/common/fixed_bands.hpp"

namespace icewatch::volume {

namespace {

cv::Matx33d skew(const cv::Vec3d& v) { return {0, -v[2], v[1], v[2], 0, -v[0], -v[1], v[0], 0}; }

// What pairAgrees and pairChi2 work out of a pair's covariance under one set of options, once per
// pair instead of once per pair and candidate: the fit asks it of every pair for each of its
// hundreds of RANSAC draws, and the inverse was most of the registration's time. The same
// expressions, so the same bits.
struct WeightedPair {
    cv::Matx33d covariance;
    cv::Matx33d weight;  // the covariance's inverse
    double riseSigma = 0;
};

WeightedPair weigh(const PointPair& pair, const RigidMotionOptions& o) {
    WeightedPair w;
    w.covariance = pairCovariance(pair, o);
    w.weight = w.covariance.inv(cv::DECOMP_CHOLESKY);
    if (cv::norm(o.riseAxis) != 0) w.riseSigma = std::sqrt((o.riseAxis.t() * w.covariance * o.riseAxis)(0));
    return w;
}

std::vector<WeightedPair> weighted(const std::vector<PointPair>& pairs, const RigidMotionOptions& o) {
    std::vector<WeightedPair> out;
    out.reserve(pairs.size());
    for (const PointPair& pair : pairs) out.push_back(weigh(pair, o));
    return out;
}

// Where the transform leaves the current point against the baseline's, and its squared
// Mahalanobis length.
cv::Vec3d residual(const PointPair& pair, const RigidTransform& transform) {
    return transform.apply(pair.current) - pair.baseline;
}
double chi2(const cv::Vec3d& r, const WeightedPair& w) { return (r.t() * w.weight * r)(0); }

// pairAgrees from the pair's residual and weights.
bool agrees(const cv::Vec3d& r, const WeightedPair& w, const RigidMotionOptions& o) {
    if (chi2(r, w) >= o.inlierChi2) return false;
    if (cv::norm(o.riseAxis) == 0) return true;
    return r.dot(o.riseAxis) <= o.riseSigmas * w.riseSigma;
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

// The displacement is measured in the camera frame; rotating the current point rotates its error
// too, but the motions here are fractions of a degree: the covariance is used as it is.
cv::Matx33d pairCovariance(const PointPair& pair, const RigidMotionOptions& o) {
    return pair.covarianceMm2 * o.covarianceScale;
}

double pairChi2(const PointPair& pair, const RigidTransform& transform, const RigidMotionOptions& o) {
    return chi2(residual(pair, transform), weigh(pair, o));
}

bool pairAgrees(const PointPair& pair, const RigidTransform& transform, const RigidMotionOptions& o) {
    return agrees(residual(pair, transform), weigh(pair, o), o);
}

double propagate(const cv::Vec6d& gradient, const cv::Matx66d& covariance) {
    return std::sqrt(std::max(0.0, (gradient.t() * covariance * gradient)(0)));
}

RigidMotion fitRigidMotion(const std::vector<PointPair>& pairs, const RigidMotionOptions& options, int minPairs) {
    RigidMotionOptions o = options;
    RigidMotion best;
    const int n = static_cast<int>(pairs.size());
    if (n < std::max(3, minPairs)) return best;
    // RANSAC for the consensus.
    const std::vector<WeightedPair> drawWeights = weighted(pairs, o);
    // The draws first, in order (one random sequence whatever the thread count), then their
    // consensus counted in fixed bands of draws, side by side; the first draw with the most pairs
    // wins, as counted one after the other.
    std::mt19937 random(o.seed);
    std::uniform_int_distribution<int> pick(0, n - 1);
    std::vector<RigidTransform> candidates;
    for (int k = 0; k < o.ransacIterations; ++k) {
        const int a = pick(random), b = pick(random), c = pick(random);
        if (a == b || b == c || a == c) continue;
        const cv::Vec3d ab = pairs[b].baseline - pairs[a].baseline, ac = pairs[c].baseline - pairs[a].baseline;
        if (cv::norm(ab.cross(ac)) < 1e-3 * cv::norm(ab) * cv::norm(ac) + 1.0) continue;  // nearly collinear
        try {
            candidates.push_back(fitRigid({pairs[a].current, pairs[b].current, pairs[c].current},
                                          {pairs[a].baseline, pairs[b].baseline, pairs[c].baseline}));
        } catch (const InvalidInput&) {
            continue;
        }
    }
    // A draw stops being counted once it cannot pass the most pairs an earlier draw of its band
    // found: it could not win (the first draw with the most pairs does), and it is marked -1, below
    // any count. Most draws are wrong and stop within the first third of the pairs; the winner is
    // the same as with every draw counted to its end.
    std::vector<int> counts(candidates.size(), 0);
    forEachFixedBand(candidates.size(), [&](int, std::size_t begin, std::size_t end) {
        int bandBest = -1;
        for (std::size_t k = begin; k < end; ++k) {
            int count = 0;
            for (std::size_t i = 0; i < pairs.size(); ++i) {
                count += agrees(residual(pairs[i], candidates[k]), drawWeights[i], o) ? 1 : 0;
                if (!o.countEveryDraw && count + static_cast<int>(pairs.size() - i - 1) <= bandBest) {
                    count = -1;
                    break;
                }
            }
            counts[k] = count;
            bandBest = std::max(bandBest, count);
        }
    });
    int bestCount = -1;
    RigidTransform bestTransform;
    for (std::size_t k = 0; k < candidates.size(); ++k) {
        if (counts[k] > bestCount) {
            bestCount = counts[k];
            bestTransform = candidates[k];
        }
    }
    if (bestCount < std::max(3, minPairs)) return best;
    // How honest the pairs' covariances are: the lower quartile of every pair's χ² under the
    // consensus (the upper part may be ice or mismatches) against that of a χ²₃ (1.213).
    {
        std::vector<double> d2;
        for (std::size_t i = 0; i < pairs.size(); ++i) d2.push_back(chi2(residual(pairs[i], bestTransform), drawWeights[i]));
        const auto quarter = d2.begin() + static_cast<std::ptrdiff_t>(d2.size() / 4);
        std::nth_element(d2.begin(), quarter, d2.end());
        o.covarianceScale = std::max(1.0, *quarter / 1.213);
    }
    // Gauss-Newton on the Mahalanobis distances, inliers re-selected at every step.
    const std::vector<WeightedPair> weights = weighted(pairs, o);
    RigidTransform t = bestTransform;
    cv::Matx66d normal;
    std::vector<std::uint8_t> inlier(pairs.size(), 0);
    double chi2Sum = 0;
    int count = 0;
    for (int iteration = 0; iteration <= o.refineIterations; ++iteration) {
        normal = cv::Matx66d::zeros();
        cv::Vec6d rhs(0, 0, 0, 0, 0, 0);
        chi2Sum = 0;
        count = 0;
        for (std::size_t i = 0; i < pairs.size(); ++i) {
            const cv::Vec3d q = t.apply(pairs[i].current);
            const cv::Vec3d r = q - pairs[i].baseline;
            const cv::Matx33d& w = weights[i].weight;
            inlier[i] = agrees(r, weights[i], o) ? 1 : 0;
            if (!inlier[i]) continue;
            ++count;
            chi2Sum += chi2(r, weights[i]);
            // r(ω, δt) = r + ω × q + δt  ->  J = [-[q]×  I]
            const cv::Matx33d jr = -skew(q);
            cv::Matx<double, 3, 6> j;
            for (int a = 0; a < 3; ++a)
                for (int b = 0; b < 3; ++b) {
                    j(a, b) = jr(a, b);
                    j(a, b + 3) = a == b ? 1.0 : 0.0;
                }
            normal += j.t() * w * j;
            rhs -= j.t() * w * r;
        }
        if (count < std::max(3, minPairs)) return best;
        if (iteration == o.refineIterations) break;
        cv::Vec6d update;
        if (!cv::solve(normal, rhs, update, cv::DECOMP_CHOLESKY)) return best;
        cv::Mat rotation;
        cv::Rodrigues(cv::Vec3d(update[0], update[1], update[2]), rotation);
        const cv::Matx33d dr(rotation);
        t.rotation = dr * t.rotation;
        t.translation = dr * t.translation + cv::Vec3d(update[3], update[4], update[5]);
    }
    best.ok = true;
    best.transform = t;
    best.inlier = inlier;
    best.inliers = count;
    best.covarianceScale = o.covarianceScale;
    const int dof = std::max(1, 3 * count - 6);
    best.chi2PerDof = chi2Sum / dof;
    best.covariance = normal.inv(cv::DECOMP_CHOLESKY) * (std::max(1.0, best.chi2PerDof) * o.correlationFactor);
    return best;
}

}  // namespace icewatch::volume
