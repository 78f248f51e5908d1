// Ice standing out of the outline, seen by the background it hides: which pixels changed against
// the baseline's background, and where they lie on the plane's grid.
#include "core/volume/silhouette.hpp"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

namespace icewatch::volume {
namespace {

// A sky with a gradient and its own noise in each capture, 10 % darker in the current one; the
// current capture has a bead 5 grey levels brighter than the sky it hides. Only the bead is hidden
// background: neither the light nor the noise is.
TEST(Silhouette, TheBackgroundHiddenIsWhatChangedBeyondTheLightAndTheNoise) {
    std::mt19937 random(7);
    std::normal_distribution<float> noise(0.0f, 0.4f);
    cv::Mat baseline(120, 200, CV_32F), current(120, 200, CV_32F);
    for (int y = 0; y < 120; ++y)
        for (int x = 0; x < 200; ++x) {
            const float sky = 180.0f + 0.2f * static_cast<float>(y);
            baseline.at<float>(y, x) = sky + noise(random);
            const bool bead = y >= 50 && y < 56 && x >= 40 && x < 160;
            current.at<float>(y, x) = 0.9f * sky + (bead ? 5.0f : 0.0f) + noise(random);
        }
    cv::Mat where = cv::Mat::zeros(120, 200, CV_8U);
    where.rowRange(10, 60).setTo(255);
    const cv::Mat hidden = backgroundHidden(baseline, current, where, 0.9, 3.0);
    EXPECT_GT(cv::countNonZero(hidden(cv::Rect(40, 50, 120, 6))), 0.95 * 120 * 6);
    EXPECT_LT(cv::countNonZero(hidden) - cv::countNonZero(hidden(cv::Rect(40, 50, 120, 6))), 10);
    EXPECT_EQ(cv::countNonZero(hidden.rowRange(60, 120)), 0);  // not looked at
    // A bead 1 grey level brighter than the sky, under the least change that counts, is not seen.
    for (int y = 50; y < 56; ++y)
        for (int x = 40; x < 160; ++x) current.at<float>(y, x) -= 4.0f;
    EXPECT_LT(cv::countNonZero(backgroundHidden(baseline, current, where, 0.9, 3.0)), 10);
}

TEST(Silhouette, UnreadBackgroundIsHiddenTableNothingIsReadInFrontOfAndAllTheSky) {
    cv::Mat hidden = cv::Mat::zeros(40, 60, CV_8U), baselineMeasured = hidden.clone(),
            currentMeasured = hidden.clone(), featureless = hidden.clone();
    hidden(cv::Rect(10, 10, 30, 10)).setTo(255);           // a bead hides the table here
    baselineMeasured.colRange(0, 30).setTo(255);           // the baseline read the table left of x 30
    currentMeasured(cv::Rect(20, 0, 40, 40)).setTo(255);   // the current capture reads right of x 20
    featureless(cv::Rect(50, 30, 10, 10)).setTo(255);      // the sky, in a corner
    const cv::Mat unread = unreadBackground(hidden, baselineMeasured, currentMeasured, featureless);
    EXPECT_EQ(cv::countNonZero(unread(cv::Rect(10, 10, 10, 10))), 100);  // hidden, read then, not now
    EXPECT_EQ(cv::countNonZero(unread(cv::Rect(20, 10, 20, 10))), 0);    // something is read in front
    EXPECT_EQ(cv::countNonZero(unread(cv::Rect(50, 30, 10, 10))), 100);  // featureless: always
    EXPECT_EQ(cv::countNonZero(unread), 200);
    // Without a sky, the table alone.
    EXPECT_EQ(cv::countNonZero(unreadBackground(hidden, baselineMeasured, currentMeasured, cv::Mat())), 100);
}

TEST(Silhouette, LeftOutBackgroundIsTheDrawnOutlineBeyondTheRingWhereverTheObjectWas) {
    cv::Mat drawn = cv::Mat::zeros(100, 200, CV_8U), region = drawn.clone(), regionInCurrent = drawn.clone();
    drawn(cv::Rect(20, 20, 160, 60)).setTo(255);
    region(cv::Rect(40, 40, 20, 20)).setTo(255);
    regionInCurrent(cv::Rect(45, 40, 20, 20)).setTo(255);  // moved 5 px right
    const cv::Mat leftOut = leftOutBackground(drawn, region, regionInCurrent, 10);
    EXPECT_EQ(cv::countNonZero(leftOut(cv::Rect(0, 0, 200, 20))), 0);  // outside the drawn outline
    EXPECT_FALSE(leftOut.at<std::uint8_t>(50, 50));                   // the region
    EXPECT_FALSE(leftOut.at<std::uint8_t>(50, 74));                   // within 10 px of where it went
    EXPECT_TRUE(leftOut.at<std::uint8_t>(50, 76));                    // beyond the ring of both
    EXPECT_FALSE(leftOut.at<std::uint8_t>(50, 31));                   // within 10 px of where it was
    EXPECT_TRUE(leftOut.at<std::uint8_t>(50, 29));
    EXPECT_TRUE(leftOut.at<std::uint8_t>(25, 150));
}

// A dark object on a sky with a gradient and a little noise, beside a grained table: the sky is
// featureless up to the object's edge (the window leaves the object out), the table is not.
TEST(Silhouette, FeaturelessBackgroundIsTheSkyNotTheTableNorTheObject) {
    std::mt19937 random(3);
    std::normal_distribution<float> noise(0.0f, 0.4f);
    cv::Mat grey(100, 200, CV_32F);
    for (int y = 0; y < 100; ++y)
        for (int x = 0; x < 200; ++x) {
            const float table = 120.0f + 15.0f * static_cast<float>(std::sin(0.9 * x + 0.3 * y));
            grey.at<float>(y, x) = (x < 100 ? 200.0f + 0.1f * static_cast<float>(y) : table) + noise(random);
        }
    grey(cv::Rect(30, 40, 40, 20)).setTo(60.0f);
    cv::Mat object = cv::Mat::zeros(100, 200, CV_8U);  // the object grown by 2 px, as the chain gives it
    object(cv::Rect(28, 38, 44, 24)).setTo(255);
    const cv::Mat featureless = featurelessBackground(grey, object, 1.0);
    EXPECT_TRUE(featureless.at<std::uint8_t>(10, 50));
    EXPECT_TRUE(featureless.at<std::uint8_t>(37, 50));   // 3 px from the object's edge
    EXPECT_FALSE(featureless.at<std::uint8_t>(50, 50));  // the object itself
    EXPECT_FALSE(featureless.at<std::uint8_t>(50, 150)); // the table
    EXPECT_EQ(cv::countNonZero(featureless.colRange(110, 200)), 0);
}

// A plane 1 m in front of the camera seen square on, grid nodes 1 mm apart: a node lies on the
// pixel its point projects to, after the object's motion between the captures.
TEST(Silhouette, HiddenPixelsLieOnTheNodesThatMovedOntoThem) {
    const cv::Matx33d k(1000, 0, 100, 0, 1000, 100, 0, 0, 1);
    PlaneFrame plane;
    plane.origin = {0, 0, 1000};
    plane.axisU = {1, 0, 0};
    plane.axisV = {0, 1, 0};
    plane.normal = {0, 0, -1};
    GridSpec grid = makeGrid(-50, 50, -50, 50, 1.0);
    cv::Mat hidden = cv::Mat::zeros(200, 200, CV_8U);
    hidden.at<std::uint8_t>(110, 130) = 255;  // 30 px right, 10 px down of the centre
    const cv::Mat height(grid.nv, grid.nu, CV_64F, cv::Scalar(0));
    RigidTransform still;
    cv::Mat onGrid = hiddenOnGrid(hidden, grid, plane, height, still, k);
    ASSERT_EQ(cv::countNonZero(onGrid), 1);
    const int i = static_cast<int>(std::lround((30 - grid.u0) / grid.du));
    const int j = static_cast<int>(std::lround((10 - grid.v0) / grid.dv));
    EXPECT_TRUE(onGrid.at<std::uint8_t>(j, i));
    // The object moved 5 mm right (current = baseline + 5 mm): the node 5 mm to the left now
    // shows on that pixel.
    RigidTransform moved;
    moved.translation = {-5, 0, 0};  // current onto baseline
    onGrid = hiddenOnGrid(hidden, grid, plane, height, moved, k);
    ASSERT_EQ(cv::countNonZero(onGrid), 1);
    EXPECT_TRUE(onGrid.at<std::uint8_t>(j, i - static_cast<int>(std::lround(5 / grid.du))));
}

// Pixels that changed alone, scattered beside an edge (the noise's tail, a JPEG block's ringing
// where the edge moved), are not background hidden by anything; a band is, whole, with the thin
// end it tapers to.
TEST(Silhouette, ScatteredPixelsAreNotHiddenBackgroundABandIs) {
    std::mt19937 random(11);
    std::normal_distribution<float> noise(0.0f, 0.4f);
    cv::Mat baseline(120, 200, CV_32F), current(120, 200, CV_32F);
    for (int y = 0; y < 120; ++y)
        for (int x = 0; x < 200; ++x) {
            baseline.at<float>(y, x) = 200.0f + noise(random);
            current.at<float>(y, x) = 200.0f + noise(random);
        }
    for (int x = 10; x < 190; x += 7) current.at<float>(30 + (x % 3), x) += 12.0f;  // single pixels
    for (int x = 12; x < 190; x += 23) current(cv::Rect(x, 40, 2, 1)) += 12.0f;     // pairs
    current(cv::Rect(60, 50, 80, 4)) += 12.0f;                                      // a bead's band
    current(cv::Rect(140, 51, 20, 1)) += 12.0f;                                     // its thin end
    cv::Mat where = cv::Mat::zeros(120, 200, CV_8U);
    where.rowRange(20, 60).setTo(255);
    const cv::Mat hidden = backgroundHidden(baseline, current, where, 1.0, 3.0);
    EXPECT_EQ(cv::countNonZero(hidden.rowRange(20, 45)), 0);
    EXPECT_EQ(cv::countNonZero(hidden(cv::Rect(60, 50, 80, 4))), 80 * 4);
    EXPECT_EQ(cv::countNonZero(hidden(cv::Rect(140, 51, 20, 1))), 20);
}

TEST(Silhouette, AnObjectsObliquityIsItsNormalsAngleToTheRayToIt) {
    PlaneFrame plane;
    plane.origin = {0.0, 0.0, 850.0};
    plane.axisU = {1.0, 0.0, 0.0};
    plane.axisV = {0.0, 1.0, 0.0};
    plane.normal = {0.0, 0.0, -1.0};
    EXPECT_NEAR(viewObliquityDeg(plane), 0.0, 1e-4);  // acos near 1
    const double turn = 20.0 * CV_PI / 180.0;
    plane.normal = {0.0, std::sin(turn), -std::cos(turn)};
    EXPECT_NEAR(viewObliquityDeg(plane), 20.0, 1e-4);
    // Off the axis, facing the camera head-on is facing along the ray to it.
    plane.origin = {300.0, 0.0, 850.0};
    plane.normal = -cv::normalize(plane.origin);
    EXPECT_NEAR(viewObliquityDeg(plane), 0.0, 1e-4);
}

}  // namespace
}  // namespace icewatch::volume
