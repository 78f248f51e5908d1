#include "core/volume/registration.hpp"

#include <cmath>

#include "core/volume/height_grid.hpp"

#include <opencv2/calib3d.hpp>
#include <gtest/gtest.h>

namespace icewatch::volume {
namespace {

// An organised cloud of a bumpy surface 800 mm away (bumps short enough to pin all six degrees
// of freedom: directions a surface leaves free are deliberately not estimated), as a 320×240 camera with f = 300 sees it.
cv::Mat wavySurface(const cv::Matx34d& p) {
    cv::Mat cloud(240, 320, CV_32FC3);
    for (int y = 0; y < 240; ++y)
        for (int x = 0; x < 320; ++x) {
            const double rx = (x - p(0, 2)) / p(0, 0), ry = (y - p(1, 2)) / p(1, 1);
            double z = 800;
            for (int k = 0; k < 5; ++k) {  // fixed point: z = 800 + bumps(X, Y)
                const double bx = rx * z, by = ry * z;
                z = 800 + 20 * std::sin(bx / 12) * std::cos(by / 10) + 0.05 * bx;
            }
            cloud.at<cv::Vec3f>(y, x) = cv::Vec3f(static_cast<float>(rx * z), static_cast<float>(ry * z), static_cast<float>(z));
        }
    return cloud;
}

TEST(Registration, RecoversAKnownRigidShift) {
    const cv::Matx34d projection(300, 0, 160, 0, 0, 300, 120, 0, 0, 0, 1, 0);
    const cv::Mat baseline = wavySurface(projection);
    const cv::Mat normals = organizedNormals(baseline, 2);
    const cv::Mat mask(baseline.size(), CV_8U, cv::Scalar(255));
    // The current capture: the same surface moved by a known motion (its inverse maps back).
    cv::Mat rvec = (cv::Mat_<double>(3, 1) << 0.004, -0.003, 0.002), r;
    cv::Rodrigues(rvec, r);
    RigidTransform truth{cv::Matx33d(r), {2.0, -1.5, 3.0}};
    std::vector<cv::Vec3d> current;
    for (int y = 20; y < 220; y += 2)
        for (int x = 20; x < 300; x += 2) {
            const cv::Vec3f q = baseline.at<cv::Vec3f>(y, x);
            current.push_back(truth.rotation.t() * (cv::Vec3d(q[0], q[1], q[2]) - truth.translation));
        }
    const RegistrationResult result =
        registerPointToPlane(baseline, normals, mask, projection, current, {}, {}, RegistrationOptions{});
    ASSERT_TRUE(result.converged);
    EXPECT_LT(cv::norm(result.transform.translation - truth.translation), 0.1);
    EXPECT_LT(cv::norm(result.transform.rotation - truth.rotation, cv::NORM_INF), 2e-4);
    EXPECT_LT(result.sigmaMm, 0.1);
}

}  // namespace
}  // namespace icewatch::volume

namespace icewatch::volume {
namespace {

// A blade-like strip 800 × 100 mm, sampled every 5 mm, in a plane frame that is the camera's own.
std::vector<cv::Vec3d> stripSamples() {
    std::vector<cv::Vec3d> samples;
    for (double u = -400; u <= 400; u += 5)
        for (double v = -50; v <= 50; v += 5) samples.emplace_back(u, v, 0.0);
    return samples;
}

PlaneFrame cameraPlane() {
    PlaneFrame plane;
    plane.origin = {0, 0, 0};
    plane.axisU = {1, 0, 0};
    plane.axisV = {0, 1, 0};
    plane.normal = {0, 0, 1};
    return plane;
}

TEST(Registration, SupportSpanSeesAPatchAtOneEnd) {
    const std::vector<cv::Vec3d> samples = stripSamples();
    std::vector<std::uint8_t> root(samples.size()), everywhere(samples.size(), 1), rearHalf(samples.size());
    for (std::size_t i = 0; i < samples.size(); ++i) {
        root[i] = samples[i][0] < -250;      // the first fifth of the span, whole chord
        rearHalf[i] = samples[i][1] >= 0;    // along the whole span, half the chord
    }
    const RigidTransform identity;
    EXPECT_DOUBLE_EQ(supportSpanPercent(samples, everywhere, identity, cameraPlane()), 100.0);
    EXPECT_DOUBLE_EQ(supportSpanPercent(samples, {}, identity, cameraPlane()), 100.0);
    // Two tenths of the span, and under a third of each chord bin's samples.
    EXPECT_DOUBLE_EQ(supportSpanPercent(samples, root, identity, cameraPlane()), 0.0);
    // Half the chord over the whole span covers every span bin and half the chord bins.
    EXPECT_DOUBLE_EQ(supportSpanPercent(samples, rearHalf, identity, cameraPlane()), 50.0);
}

TEST(Registration, SupportSpanIgnoresScatteredPatches) {
    const std::vector<cv::Vec3d> samples = stripSamples();
    std::vector<std::uint8_t> patches(samples.size());
    for (std::size_t i = 0; i < samples.size(); ++i) {
        const double u = samples[i][0], v = samples[i][1];
        // The root, plus three small patches further out: under a third of their bins' samples.
        patches[i] = u < -250 || (std::abs(v) <= 10 && (std::abs(u) <= 10 || std::abs(u - 150) <= 10 || std::abs(u - 300) <= 10));
    }
    EXPECT_LT(supportSpanPercent(samples, patches, RigidTransform{}, cameraPlane()), 50.0);
}

TEST(Registration, SupportSpanFollowsTheTransform) {
    // Moving the samples does not change the share: both the region and the support move.
    const std::vector<cv::Vec3d> samples = stripSamples();
    std::vector<std::uint8_t> root(samples.size());
    for (std::size_t i = 0; i < samples.size(); ++i) root[i] = samples[i][0] < -250;
    RigidTransform moved;
    moved.translation = {7, -3, 2};
    EXPECT_DOUBLE_EQ(supportSpanPercent(samples, root, moved, cameraPlane()),
                     supportSpanPercent(samples, root, RigidTransform{}, cameraPlane()));
    EXPECT_EQ(supportSpanPercent({}, {}, RigidTransform{}, cameraPlane()), 0.0);
}

}  // namespace
}  // namespace icewatch::volume
