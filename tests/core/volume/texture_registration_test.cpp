#include "core/volume/texture_registration.hpp"

#include <cmath>

#include "core/common/error.hpp"

#include <opencv2/imgproc.hpp>
#include <gtest/gtest.h>

namespace icewatch::volume {
namespace {

constexpr double kF = 300, kCx = 160, kCy = 120, kDepthMm = 800;

// A textured extruded surface (a shallow ridge along x, the same at every x: shape alone cannot
// tell a slide along x) seen by a 320×240 camera. The object is moved in its plane by `shiftMm`
// along x and turned by `turnDeg` about the view axis; the image is its texture, the cloud its
// points, as a camera with exact disparities would give them.
void renderExtruded(double shiftMm, double turnDeg, cv::Mat& grey, cv::Mat& cloud) {
    cv::Mat pattern(512, 512, CV_32F);
    cv::setRNGSeed(7);
    cv::randu(pattern, 0, 1);
    cv::GaussianBlur(pattern, pattern, {0, 0}, 3.0);
    cv::normalize(pattern, pattern, 0, 1, cv::NORM_MINMAX);
    const double c = std::cos(turnDeg * CV_PI / 180), s = std::sin(turnDeg * CV_PI / 180);
    grey.create(240, 320, CV_8U);
    cloud.create(240, 320, CV_32FC3);
    for (int y = 0; y < 240; ++y)
        for (int x = 0; x < 320; ++x) {
            const double rx = (x - kCx) / kF, ry = (y - kCy) / kF;
            double z = kDepthMm;
            for (int k = 0; k < 4; ++k) z = kDepthMm - 10 * std::cos(ry * z / 60);  // ridge across y
            const double wx = rx * z, wy = ry * z;
            // Object coordinates: undo the motion.
            const double ox = c * wx + s * wy - shiftMm, oy = -s * wx + c * wy;
            cv::Mat texel;  // bilinear: the texture moves smoothly with the object
            cv::getRectSubPix(pattern, {1, 1}, cv::Point2f(static_cast<float>(ox + 256), static_cast<float>(oy + 256)), texel);
            grey.at<std::uint8_t>(y, x) = cv::saturate_cast<std::uint8_t>(60 + 140 * texel.at<float>(0, 0));
            cloud.at<cv::Vec3f>(y, x) = cv::Vec3f(static_cast<float>(wx), static_cast<float>(wy), static_cast<float>(z));
        }
}

TEST(TextureRegistration, RecoversAnInPlaneShiftAlongAnExtrudedSurface) {
    cv::Mat baselineGrey, baselineCloud, currentGrey, currentCloud;
    renderExtruded(0.0, 0.0, baselineGrey, baselineCloud);
    renderExtruded(3.0, 0.4, currentGrey, currentCloud);
    const PlaneFrame plane{{0, 0, kDepthMm}, {1, 0, 0}, {0, -1, 0}, {0, 0, -1}};
    const cv::Mat mask(baselineGrey.size(), CV_8U, cv::Scalar(255));
    const TextureRegistrationResult r =
        registerByTexture(baselineGrey, baselineCloud, currentGrey, currentCloud, mask, plane);
    ASSERT_TRUE(r.ok);
    EXPECT_GT(r.inliers, 50);
    // current -> baseline undoes the motion: a point of the current capture at the centre goes
    // back by the shift (the turn about the centre moves the centre itself by nothing).
    const cv::Vec3d centre(0, 0, kDepthMm - 10);
    const cv::Vec3d moved = r.transform.apply(centre);
    EXPECT_NEAR(moved[0] - centre[0], -3.0, 0.1);
    EXPECT_NEAR(moved[1] - centre[1], 0.0, 0.1);
    EXPECT_NEAR(moved[2] - centre[2], 0.0, 1e-6);  // no out-of-plane motion is estimated
    const double turnDeg = std::atan2(r.transform.rotation(1, 0), r.transform.rotation(0, 0)) * 180 / CV_PI;
    EXPECT_NEAR(turnDeg, -0.4, 0.05);
}

TEST(TextureRegistration, RefusesAnImageWithoutTexture) {
    cv::Mat cloud;
    cv::Mat grey;
    renderExtruded(0.0, 0.0, grey, cloud);
    const cv::Mat flat(grey.size(), CV_8U, cv::Scalar(128));
    const PlaneFrame plane{{0, 0, kDepthMm}, {1, 0, 0}, {0, -1, 0}, {0, 0, -1}};
    const TextureRegistrationResult r =
        registerByTexture(flat, cloud, flat, cloud, cv::Mat(grey.size(), CV_8U, cv::Scalar(255)), plane);
    EXPECT_FALSE(r.ok);
}

TEST(TextureRegistration, FitRigidRecoversAKnownTransform) {
    const cv::Matx33d rotation(std::cos(0.1), -std::sin(0.1), 0, std::sin(0.1), std::cos(0.1), 0, 0, 0, 1);
    const cv::Vec3d translation(1, -2, 3);
    std::vector<cv::Vec3d> from{{0, 0, 800}, {50, 0, 810}, {0, 40, 790}, {30, 30, 805}}, to;
    for (const auto& p : from) to.push_back(rotation * p + translation);
    const RigidTransform t = fitRigid(from, to);
    EXPECT_LT(cv::norm(t.translation - translation), 1e-6);
    EXPECT_LT(cv::norm(t.rotation - rotation, cv::NORM_INF), 1e-9);
    EXPECT_THROW(fitRigid({from[0], from[1]}, {to[0], to[1]}), InvalidInput);
}

}  // namespace
}  // namespace icewatch::volume
