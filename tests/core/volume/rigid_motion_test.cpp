#include "core/volume/rigid_motion.hpp"

#include <cmath>
#include <random>

#include <opencv2/calib3d.hpp>
#include <gtest/gtest.h>

namespace icewatch::volume {
namespace {

cv::Matx33d rotation(const cv::Vec3d& radians) {
    cv::Mat r;
    cv::Rodrigues(radians, r);
    return cv::Matx33d(r);
}

// Points on a blade-like strip 850 mm away; each pair's error mostly along the line of sight, as
// stereo gives it; a share of them "iced": moved towards the camera by a few millimetres.
TEST(RigidMotion, RecoversAKnown6DofMotionWithinItsCovariance) {
    std::mt19937 random(3);
    std::normal_distribution<double> gauss(0.0, 1.0);
    RigidTransform truth;  // current -> baseline
    truth.rotation = rotation({0.004, -0.003, 0.005});
    truth.translation = {1.5, -2.0, 2.5};
    const RigidTransform inverse{truth.rotation.t(), -(truth.rotation.t() * truth.translation)};
    int trials = 0, covered = 0;
    for (int trial = 0; trial < 20; ++trial) {
        std::vector<PointPair> pairs;
        std::vector<bool> iced;
        for (double u = -400; u <= 400; u += 20)
            for (double v = -50; v <= 50; v += 20) {
                const cv::Vec3d baseline(u, v + 0.02 * u, 850 + 0.05 * u + 10 * std::sin(v / 30));
                cv::Vec3d current = inverse.apply(baseline);
                const double sLateral = 0.05, sDepth = 0.4;
                const cv::Vec3d sight = cv::normalize(current);
                cv::Vec3d a = cv::normalize(sight.cross(cv::Vec3d(0, 1, 0))), b = sight.cross(a);
                current += sLateral * gauss(random) * a + sLateral * gauss(random) * b + sDepth * gauss(random) * sight;
                const cv::Matx33d c = sLateral * sLateral * (a * a.t() + b * b.t()) + sDepth * sDepth * (sight * sight.t());
                const bool ice = v > 0 && u > -200;  // the leading half of most of the span
                if (ice) current -= cv::Vec3d(0, 0, 3.0);
                pairs.push_back({current, baseline, c});
                iced.push_back(ice);
            }
        RigidMotionOptions options;
        options.seed = static_cast<std::uint32_t>(trial + 1);
        options.riseAxis = {0, 0, -1};  // towards the camera
        const RigidMotion m = fitRigidMotion(pairs, options);
        ASSERT_TRUE(m.ok);
        int icedInliers = 0;
        for (std::size_t i = 0; i < pairs.size(); ++i) icedInliers += iced[i] && m.inlier[i] ? 1 : 0;
        EXPECT_EQ(icedInliers, 0);
        // The error as a left perturbation: truth = exp(ω)·fit + δt.
        const cv::Matx33d dr = truth.rotation * m.transform.rotation.t();
        cv::Vec3d omega;
        cv::Rodrigues(cv::Mat(dr), omega);
        const cv::Vec3d dt = truth.translation - dr * m.transform.translation;
        const cv::Vec6d error(omega[0], omega[1], omega[2], dt[0], dt[1], dt[2]);
        const double chi2 = (error.t() * m.covariance.inv(cv::DECOMP_CHOLESKY) * error)(0);
        ++trials;
        covered += chi2 < 16.8 ? 1 : 0;  // χ² with 6 dof at 99 %
    }
    EXPECT_GE(covered, trials - 1);
}

// Through perspective, where the points are seen says how far the object moved towards the camera
// and how it tilted: a pair's position across the view is known some twenty times better than its
// depth, and a fit that weighs each pair by its own covariance must use that. Measured at a point
// beside the pairs along the normal, as the ice on a leading edge beside the clean surface: the
// fit's error there must come near the least any fit of these pairs can make (from the pairs'
// true covariances), and far below what their depths alone would give.
TEST(RigidMotion, ThePairsPrecisionAcrossTheViewFixesTheMotionsDepth) {
    const RigidTransform truth{rotation({0.003, -0.004, 0.002}), {0.6, -0.4, 1.5}};  // current -> baseline
    const RigidTransform inverse{truth.rotation.t(), -(truth.rotation.t() * truth.translation)};
    const cv::Vec3d beside(0, 90, 850);  // where the ice would be
    const cv::Vec6d gradient(beside[1], -beside[0], 0, 0, 0, 1);  // d(z of exp(ω)·x + δt) / d(ω, δt) at it
    const auto depthErrorAtIce = [&](const RigidTransform& fit) {
        return (fit.apply(inverse.apply(beside)) - beside)[2];
    };
    std::mt19937 random(5);
    std::normal_distribution<double> gauss(0.0, 1.0);
    double sumSquaresAsMeasured = 0, sumSquaresDepthAlone = 0, leastVariance = 0;
    int coveredAsMeasured = 0;
    const int trials = 40;
    for (int trial = 0; trial < trials; ++trial) {
        std::vector<PointPair> asMeasured, depthAlone;
        cv::Matx66d information = cv::Matx66d::zeros();
        for (double u = -400; u <= 400; u += 20)
            for (double v = -60; v <= 40; v += 20) {
                const cv::Vec3d baseline(u, v, 850 + 0.05 * u);
                const cv::Vec3d sight = cv::normalize(inverse.apply(baseline));
                const cv::Vec3d a = cv::normalize(sight.cross(cv::Vec3d(0, 1, 0))), b = sight.cross(a);
                const double sLateral = 0.02, sDepth = 0.5;
                const cv::Vec3d current = inverse.apply(baseline) + sLateral * gauss(random) * a +
                                          sLateral * gauss(random) * b + sDepth * gauss(random) * sight;
                const cv::Matx33d lateral = a * a.t() + b * b.t(), along = sight * sight.t();
                const cv::Matx33d covariance = sLateral * sLateral * lateral + sDepth * sDepth * along;
                asMeasured.push_back({current, baseline, covariance});
                // The same pairs, their position across the view taken as no better than their depth.
                depthAlone.push_back({current, baseline, sDepth * sDepth * (lateral + along)});
                if (trial == 0) {
                    cv::Matx<double, 3, 6> j = cv::Matx<double, 3, 6>::zeros();
                    const cv::Vec3d& q = baseline;  // r(ω, δt) = r + ω × q + δt
                    j(0, 1) = q[2], j(0, 2) = -q[1], j(1, 0) = -q[2], j(1, 2) = q[0], j(2, 0) = q[1], j(2, 1) = -q[0];
                    for (int k = 0; k < 3; ++k) j(k, k + 3) = 1;
                    information += j.t() * covariance.inv() * j;
                }
            }
        if (trial == 0) leastVariance = (gradient.t() * information.inv() * gradient)(0);
        RigidMotionOptions options;
        options.seed = static_cast<std::uint32_t>(trial + 1);
        const RigidMotion fit = fitRigidMotion(asMeasured, options);
        const RigidMotion depthOnly = fitRigidMotion(depthAlone, options);
        ASSERT_TRUE(fit.ok);
        ASSERT_TRUE(depthOnly.ok);
        const double e = depthErrorAtIce(fit.transform), eDepth = depthErrorAtIce(depthOnly.transform);
        sumSquaresAsMeasured += e * e;
        sumSquaresDepthAlone += eDepth * eDepth;
        coveredAsMeasured += std::abs(e) <= 2.0 * propagate(gradient, fit.covariance) ? 1 : 0;  // k = 2
    }
    const double rmsAsMeasured = std::sqrt(sumSquaresAsMeasured / trials);
    const double rmsDepthAlone = std::sqrt(sumSquaresDepthAlone / trials);
    const double least = std::sqrt(leastVariance);
    EXPECT_LT(rmsAsMeasured, 1.25 * least) << rmsAsMeasured << " mm against the least " << least;
    EXPECT_LT(rmsAsMeasured, 0.3 * rmsDepthAlone) << rmsAsMeasured << " mm against " << rmsDepthAlone;
    EXPECT_GE(coveredAsMeasured, trials * 9 / 10);
}

TEST(RigidMotion, DrawsThatCannotWinStopBeingCountedAndTheFitStaysTheSame) {
    // A third of the pairs iced (risen 3 mm) and a fifth mismatched anywhere within 20 mm: most
    // draws hold a wrong pair and stop early; the plain count of every draw must pick the same.
    // The pairs scatter more than their covariance says, so that the good draws' counts differ
    // by a few pairs and the winner is one draw among many close to it.
    std::mt19937 random(11);
    std::normal_distribution<double> gauss(0.0, 0.3);
    std::uniform_real_distribution<double> anywhere(-20.0, 20.0);
    const RigidTransform motion{rotation({0.002, 0.001, -0.003}), {0.8, -0.5, 1.2}};
    std::vector<PointPair> pairs;
    int index = 0;
    for (double u = -300; u <= 300; u += 15)
        for (double v = -60; v <= 60; v += 15, ++index) {
            const cv::Vec3d baseline(u, v, 850 + 0.04 * u);
            cv::Vec3d current = motion.apply(baseline) + cv::Vec3d(gauss(random), gauss(random), gauss(random));
            if (index % 3 == 0) current -= cv::Vec3d(0, 0, 3.0);
            if (index % 5 == 1) current += cv::Vec3d(anywhere(random), anywhere(random), anywhere(random));
            pairs.push_back({current, baseline, cv::Matx33d::eye() * 0.04});
        }
    for (std::uint32_t seed = 1; seed <= 5; ++seed) {
        RigidMotionOptions fast;
        fast.seed = seed;
        fast.riseAxis = {0, 0, -1};
        RigidMotionOptions plain = fast;
        plain.countEveryDraw = true;
        const RigidMotion a = fitRigidMotion(pairs, fast), b = fitRigidMotion(pairs, plain);
        ASSERT_TRUE(a.ok && b.ok) << seed;
        EXPECT_EQ(a.inliers, b.inliers) << seed;
        EXPECT_EQ(a.inlier, b.inlier) << seed;
        EXPECT_EQ(cv::norm(a.transform.rotation - b.transform.rotation), 0.0) << seed;
        EXPECT_EQ(cv::norm(a.transform.translation - b.transform.translation), 0.0) << seed;
        EXPECT_GT(a.inliers, static_cast<int>(pairs.size()) / 3) << seed;
    }
}

TEST(RigidMotion, TooFewPairsIsNotAFit) {
    std::vector<PointPair> pairs{{{0, 0, 800}, {0, 0, 800}, cv::Matx33d::eye()}, {{10, 0, 800}, {10, 0, 800}, cv::Matx33d::eye()}};
    EXPECT_FALSE(fitRigidMotion(pairs).ok);
}

}  // namespace
}  // namespace icewatch::volume
