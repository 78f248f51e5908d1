#include "core/volume/slanted_refinement.hpp"

#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

namespace icewatch::volume {
namespace {

// A band-limited texture along x (wavelengths 5 to 24 px, phases varying from row to row) that
// can be sampled anywhere: the right eye is rendered exactly, with no interpolation of its own.
class Texture {
public:
    explicit Texture(unsigned seed) {
        std::mt19937 random(seed);
        std::uniform_real_distribution<double> wavelength(5.0, 24.0), phase(0.0, 2.0 * CV_PI), rowRate(-0.3, 0.3);
        for (int k = 0; k < 12; ++k) waves_.push_back({2.0 * CV_PI / wavelength(random), phase(random), rowRate(random)});
    }
    // Grey levels around 120, a weak texture of a few grey levels as on the blade's composite.
    double operator()(double x, int y) const {
        double sum = 0;
        for (const Wave& w : waves_) sum += std::sin(w.frequency * x + w.phase + w.rowRate * y);
        return 120.0 + 1.5 * sum;
    }

private:
    struct Wave {
        double frequency, phase, rowRate;
    };
    std::vector<Wave> waves_;
};

// A plane whose disparity is d0 + a·x + b·y, seen by both eyes: left(x) = T(x), and the right eye
// sees the left's x at x - d(x, y).
struct SlantedScene {
    cv::Mat left, right, truth;
};

SlantedScene slantedPlane(double d0, double a, double b, double gain, double offset) {
    const Texture texture(7);
    const cv::Size size(240, 120);
    SlantedScene s{cv::Mat(size, CV_32F), cv::Mat(size, CV_32F), cv::Mat(size, CV_32F)};
    for (int y = 0; y < size.height; ++y) {
        for (int x = 0; x < size.width; ++x) {
            s.left.at<float>(y, x) = static_cast<float>(texture(x, y));
            s.truth.at<float>(y, x) = static_cast<float>(d0 + a * x + b * y);
            // The left x that lands on right x: x_l - (d0 + a·x_l + b·y) = x.
            const double xl = (x + d0 + b * y) / (1.0 - a);
            s.right.at<float>(y, x) = static_cast<float>(gain * texture(xl, y) + offset);
        }
    }
    return s;
}

// What a window that assumes a surface facing the camera returns on a slant: runs of one value,
// stepping by `step` (the matcher's sub-pixel stages leave steps of a fraction of a pixel).
cv::Mat staircase(const cv::Mat& truth, double step) {
    cv::Mat steps = truth.clone();
    for (int y = 0; y < steps.rows; ++y) {
        for (int x = 0; x < steps.cols; ++x) {
            float& d = steps.at<float>(y, x);
            d = static_cast<float>(std::round(d / step) * step);
        }
    }
    return steps;
}

double meanAbsoluteError(const cv::Mat& disparity, const cv::Mat& truth, const cv::Rect& area) {
    return cv::mean(cv::abs(disparity(area) - truth(area)))[0];
}

TEST(SlantedRefinement, TakesTheStaircaseOffASurfaceTurnedOutOfTheView) {
    // 0.08 px of disparity per row: a surface turned 45° about the image's horizontal axis at
    // 850 mm, as a blade on a table seen from above at an angle.
    const SlantedScene s = slantedPlane(30.0, 0.01, 0.08, 1.0, 0.0);
    cv::Mat disparity = staircase(s.truth, 0.75);
    const cv::Rect area(40, 20, 160, 80);
    const double before = meanAbsoluteError(disparity, s.truth, area);
    ASSERT_GT(before, 0.15);
    const SlantedRefinementCount n = refineSlanted(s.left, s.right, area, SlantedRefinement{}, disparity);
    EXPECT_GT(n.refined, area.area() * 97 / 100);
    EXPECT_LT(meanAbsoluteError(disparity, s.truth, area), 0.01);
    // Outside the area nothing changed.
    EXPECT_EQ(disparity.at<float>(5, 5), staircase(s.truth, 0.75).at<float>(5, 5));
}

TEST(SlantedRefinement, IsUnbiasedAtEveryFractionOfAPixel) {
    // A facing surface at fractional disparities: the interpolator must not pull them to the pixels.
    for (double d0 : {20.0, 20.25, 20.5, 20.75}) {
        const SlantedScene s = slantedPlane(d0, 0.0, 0.0, 1.0, 0.0);
        cv::Mat disparity(s.truth.size(), CV_32F, cv::Scalar(std::round(d0)));
        const cv::Rect area(40, 20, 160, 80);
        refineSlanted(s.left, s.right, area, SlantedRefinement{}, disparity);
        EXPECT_NEAR(cv::mean(disparity(area))[0], d0, 0.002) << d0;
    }
}

TEST(SlantedRefinement, IgnoresAChangeOfLightBetweenTheEyes) {
    const SlantedScene s = slantedPlane(30.0, 0.0, -0.05, 1.15, -8.0);
    cv::Mat disparity = staircase(s.truth, 1.0);
    const cv::Rect area(40, 20, 160, 80);
    refineSlanted(s.left, s.right, area, SlantedRefinement{}, disparity);
    EXPECT_LT(meanAbsoluteError(disparity, s.truth, area), 0.01);
}

TEST(SlantedRefinement, LeavesWhatItCannotTellToTheMatcher) {
    // A blank surface (ice, sky) and invalid pixels: the matcher's values stand, the holes stay.
    cv::Mat blank(120, 240, CV_32F, cv::Scalar(200));
    cv::Mat disparity(blank.size(), CV_32F, cv::Scalar(25.0f));
    disparity(cv::Rect(100, 50, 10, 10)).setTo(-1.0f);
    const cv::Mat matched = disparity.clone();
    const SlantedRefinementCount n =
        refineSlanted(blank, blank, cv::Rect(20, 20, 200, 80), SlantedRefinement{}, disparity);
    EXPECT_EQ(n.refined, 0);
    EXPECT_EQ(n.kept, 200 * 80 - 100);
    EXPECT_EQ(cv::countNonZero(disparity != matched), 0);
}

TEST(SlantedRefinement, KeepsTheMatchersValueWhereTheWindowFindsAnotherSurface) {
    // Started three pixels off on a repeating texture: the window may lock onto another period,
    // further than max_change from where it started, and then the matcher's value stands.
    const SlantedScene s = slantedPlane(30.0, 0.0, 0.0, 1.0, 0.0);
    SlantedRefinement p;
    p.maxChangePx = 0.5;
    cv::Mat disparity(s.truth.size(), CV_32F, cv::Scalar(33.0f));
    refineSlanted(s.left, s.right, cv::Rect(40, 20, 160, 80), p, disparity);
    cv::Mat moved = cv::abs(disparity - 33.0f) > 0.5f;
    EXPECT_EQ(cv::countNonZero(moved), 0);
}

}  // namespace
}  // namespace icewatch::volume
