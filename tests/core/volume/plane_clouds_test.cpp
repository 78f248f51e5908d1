#include "core/volume/plane_clouds.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace icewatch::volume {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// A flat patch at 800 mm in a 60x40 frame, points only in columns 12..40 and rows 7..30 (the
// current capture's a little wider than the baseline's).
cv::Mat patchPoints(cv::Rect where) {
    cv::Mat points(40, 60, CV_32FC3, cv::Scalar::all(kNaN));
    for (int y = where.y; y < where.br().y; ++y)
        for (int x = where.x; x < where.br().x; ++x) points.at<cv::Vec3f>(y, x) = cv::Vec3f(x - 30.f, y - 20.f, 800.f);
    return points;
}

// The plane z = 800 mm, its normal towards the camera.
PlaneFrame facingPlane() {
    PlaneFrame plane;
    plane.origin = {0, 0, 800};
    plane.axisU = {1, 0, 0};
    plane.axisV = {0, 1, 0};
    plane.normal = {0, 0, -1};
    return plane;
}

TEST(PlaneClouds, MapsCoverThePointsBoxAndHoldEachPixelsPoint) {
    const cv::Rect baselineRect(14, 7, 25, 24), currentRect(12, 9, 29, 20);
    const cv::Mat baseline = patchPoints(baselineRect), current = patchPoints(currentRect);
    const cv::Mat measured(baseline.size(), CV_8U, cv::Scalar(255));
    const cv::Mat outline(baseline.size(), CV_8U, cv::Scalar(255));
    const PlaneFrame plane = facingPlane();
    RigidTransform shift;
    shift.translation = {0, 0, -0.5};  // the current capture moved 0.5 mm towards the camera
    const PlaneClouds clouds =
        planeClouds(baselineCloud(baseline, measured, plane, Parameters{}), BaselineCloud{}, current, outline,
                    cv::Mat::zeros(outline.size(), CV_8U), plane, shift, Parameters{});

    EXPECT_EQ(clouds.box, baselineRect | currentRect);
    ASSERT_EQ(clouds.baseline.size(), clouds.box.size());
    ASSERT_EQ(clouds.current.size(), clouds.box.size());
    EXPECT_EQ(clouds.currentPoints, currentRect.area());  // a flat patch has no strays
    for (int y = 0; y < clouds.box.height; ++y)
        for (int x = 0; x < clouds.box.width; ++x) {
            const cv::Point frame = clouds.box.tl() + cv::Point(x, y);
            const cv::Vec3d b = clouds.baseline.at<cv::Vec3d>(y, x), c = clouds.current.at<cv::Vec3d>(y, x);
            EXPECT_EQ(baselineRect.contains(frame), !std::isnan(b[2])) << frame;
            EXPECT_EQ(currentRect.contains(frame), !std::isnan(c[2])) << frame;
            if (!std::isnan(b[2])) {
                EXPECT_NEAR(b[0], frame.x - 30.0, 1e-9);
                EXPECT_NEAR(b[1], frame.y - 20.0, 1e-9);
                EXPECT_NEAR(b[2], 0.0, 1e-9);
            }
            if (!std::isnan(c[2])) {
                EXPECT_NEAR(c[0], frame.x - 30.0, 1e-9);
                EXPECT_NEAR(c[2], 0.5, 1e-9);
            }
        }
}

// Around the outline the current points are kept apart: ice standing out of the outline is
// measured from them alone, and the outline's own surface from the points inside it.
TEST(PlaneClouds, TheRingsPointsAreKeptApartFromTheOutlines) {
    const cv::Rect all(10, 10, 30, 20), inside(15, 15, 20, 10);
    const cv::Mat current = patchPoints(all);
    cv::Mat outline = cv::Mat::zeros(current.size(), CV_8U), ring = cv::Mat::zeros(current.size(), CV_8U);
    outline(inside).setTo(255);
    ring(all).setTo(255);
    ring(inside).setTo(0);
    const PlaneFrame plane = facingPlane();
    const PlaneClouds clouds = planeClouds(baselineCloud(current, outline, plane, Parameters{}), BaselineCloud{}, current,
                                           outline, ring, plane, RigidTransform{}, Parameters{});
    EXPECT_EQ(clouds.currentPoints, all.area());
    for (int y = 0; y < clouds.box.height; ++y)
        for (int x = 0; x < clouds.box.width; ++x) {
            const cv::Point frame = clouds.box.tl() + cv::Point(x, y);
            EXPECT_EQ(inside.contains(frame), !std::isnan(clouds.current.at<cv::Vec3d>(y, x)[2])) << frame;
            EXPECT_EQ(all.contains(frame) && !inside.contains(frame),
                      !std::isnan(clouds.currentRing.at<cv::Vec3d>(y, x)[2])) << frame;
        }
}

TEST(PlaneClouds, NoPointsGiveOneEmptyPixel) {
    const cv::Mat none(20, 30, CV_32FC3, cv::Scalar::all(kNaN));
    const cv::Mat all(none.size(), CV_8U, cv::Scalar(255));
    const PlaneFrame plane = facingPlane();
    const PlaneClouds clouds =
        planeClouds(baselineCloud(none, all, plane, Parameters{}), BaselineCloud{}, none, all,
                    cv::Mat::zeros(all.size(), CV_8U), plane, RigidTransform{}, Parameters{});
    EXPECT_EQ(clouds.box.area(), 1);
    EXPECT_EQ(clouds.currentPoints, 0);
    EXPECT_TRUE(std::isnan(clouds.current.at<cv::Vec3d>(0, 0)[2]));
}

}  // namespace
}  // namespace icewatch::volume
