#include "core/volume/raised_object.hpp"

#include <cmath>
#include <functional>
#include <limits>

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

namespace icewatch::volume {
namespace {

constexpr double kFocalPx = 1000.0;
constexpr double kTableDepthMm = 850.0;

// A table 850 mm from the camera, turned 10° about the image's x axis, seen by a pinhole of 1000 px
// over 400 x 240 pixels, with 0.6 mm of depth noise; an object over it, a slanted bar like a blade,
// whose height above the table at each of its pixels `height` gives (its distance in pixels from
// the bar's edge); a band of the frame the matcher did not measure when `unmeasuredFrom` >= 0
// (the sky beyond a table's far edge, from that row up).
struct Scene {
    cv::Mat points;  // CV_32FC3, NaN where unmeasured
    cv::Mat object;  // CV_8U, the truth
};

Scene objectOverTable(const std::function<double(double edgePx)>& height, int unmeasuredFrom = -1) {
    Scene s;
    s.object = cv::Mat::zeros(240, 400, CV_8U);
    const std::vector<cv::Point> bar{{60, 100}, {340, 80}, {345, 130}, {55, 150}};
    cv::fillConvexPoly(s.object, bar, cv::Scalar(255));
    cv::Mat edge;
    cv::distanceTransform(s.object, edge, cv::DIST_L2, cv::DIST_MASK_PRECISE);
    const double tilt = 10.0 * 3.14159265358979 / 180.0;
    const cv::Vec3d normal(0, std::sin(tilt), -std::cos(tilt));  // towards the camera
    cv::RNG rng(3);
    s.points.create(s.object.size(), CV_32FC3);
    for (int y = 0; y < s.points.rows; ++y)
        for (int x = 0; x < s.points.cols; ++x) {
            if (y < unmeasuredFrom) {
                s.points.at<cv::Vec3f>(y, x) = cv::Vec3f::all(std::numeric_limits<float>::quiet_NaN());
                continue;
            }
            const cv::Vec3d ray((x - 200) / kFocalPx, (y - 120) / kFocalPx, 1.0);
            // On the table: the ray meets the plane n·p = n·(0, 0, depth).
            const double offset = normal.dot(cv::Vec3d(0, 0, kTableDepthMm));
            cv::Vec3d p = ray * (offset / normal.dot(ray));
            if (s.object.at<std::uint8_t>(y, x)) p += height(edge.at<float>(y, x)) * normal;
            p[2] += rng.gaussian(0.6);
            s.points.at<cv::Vec3f>(y, x) = cv::Vec3f(p);
        }
    return s;
}

cv::Mat grown(const cv::Mat& mask, int px) {
    cv::Mat out;
    cv::dilate(mask, out, cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * px + 1, 2 * px + 1}));
    return out;
}

// Pixels where two masks differ, as a share of the first.
double differingShare(const cv::Mat& a, const cv::Mat& b) {
    return static_cast<double>(cv::countNonZero(a != b)) / cv::countNonZero(a);
}

// A blade standing 19 mm above its table inside an outline drawn 20 px wide: the table's margin is
// left out, to within the object's edge.
TEST(RaisedObject, TheMarginOfATableUnderARaisedObjectIsLeftOut) {
    const Scene s = objectOverTable([](double) { return 19.0; });
    const cv::Mat drawn = grown(s.object, 20);
    const RaisedObject r = objectAboveItsBackground(drawn, s.points);
    EXPECT_NEAR(r.stepMm, 19.0, 1.0);
    EXPECT_LT(differingShare(s.object, r.object), 0.05);
    EXPECT_EQ(cv::countNonZero(r.object & ~drawn), 0) << "nothing outside the outline is added";
    const double margin = 100.0 * (cv::countNonZero(drawn) - cv::countNonZero(s.object)) / cv::countNonZero(drawn);
    EXPECT_NEAR(r.backgroundPercent, margin, 3.0);
}

// An object that rises from its table gradually, as a blade lying on it does (its rim within a few
// millimetres of the table over 15 px): the flood runs into its rim, the object does not stand
// above the table where it stops, and the outline comes back as drawn.
TEST(RaisedObject, AnObjectLyingOnItsTableComesBackAsDrawn) {
    const Scene s = objectOverTable([](double edgePx) { return 0.25 * edgePx; });
    const cv::Mat drawn = grown(s.object, 20);
    const RaisedObject r = objectAboveItsBackground(drawn, s.points);
    EXPECT_GT(r.stepMm, 0.0) << "the margin was found and its edge measured";
    EXPECT_EQ(cv::countNonZero(r.object != drawn), 0);
    EXPECT_EQ(r.backgroundPercent, 0.0);
}

// Over the sky the ring outside the outline holds no measurements: there is no background plane
// to tell a margin by, and the outline comes back as drawn.
TEST(RaisedObject, AnOutlineOverAnUnmeasuredBackgroundComesBackAsDrawn) {
    Scene s = objectOverTable([](double) { return 19.0; });
    const cv::Mat drawn = grown(s.object, 20);
    s.points.setTo(cv::Scalar::all(std::numeric_limits<double>::quiet_NaN()), ~drawn);
    const RaisedObject r = objectAboveItsBackground(drawn, s.points);
    EXPECT_EQ(cv::countNonZero(r.object != drawn), 0);
    EXPECT_EQ(r.stepMm, 0.0);
}

// The outline on the object's own edge holds no margin: it comes back as drawn, whichever way the
// object stands.
TEST(RaisedObject, AnOutlineOnTheObjectsEdgeComesBackAsDrawn) {
    const Scene s = objectOverTable([](double) { return 19.0; });
    const RaisedObject r = objectAboveItsBackground(s.object, s.points);
    EXPECT_EQ(cv::countNonZero(r.object != s.object), 0);
    EXPECT_EQ(r.backgroundPercent, 0.0);
}

// A table that ends before the outline does (the sky beyond its far edge, unmeasured): the plane
// comes from the measured part of the ring, as long as it is most of it.
TEST(RaisedObject, APartlyMeasuredRingStillGivesThePlane) {
    const Scene s = objectOverTable([](double) { return 19.0; }, 55);
    const cv::Mat drawn = grown(s.object, 20);
    const RaisedObject r = objectAboveItsBackground(drawn, s.points);
    EXPECT_NEAR(r.stepMm, 19.0, 1.0);
    EXPECT_LT(differingShare(s.object, r.object), 0.05);
}

}  // namespace
}  // namespace icewatch::volume
