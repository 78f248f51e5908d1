#include "core/volume/slanted_refinement.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

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
    // The chain asks for less of the window's support there: a staircase of 0.75 px steps keeps
    // its pixels within the support's reach, but not all of their weight.
    const SlantedScene s = slantedPlane(30.0, 0.01, 0.08, 1.0, 0.0);
    cv::Mat disparity = staircase(s.truth, 0.75);
    const cv::Rect area(40, 20, 160, 80);
    const double before = meanAbsoluteError(disparity, s.truth, area);
    ASSERT_GT(before, 0.15);
    SlantedRefinement turned;
    turned.minSupportShare = kTurnedOutOfTheViewSupportShare;
    const SlantedRefinementCount n = refineSlanted(s.left, s.right, area, turned, disparity);
    EXPECT_GT(n.refined, area.area() * 97 / 100);
    EXPECT_LT(meanAbsoluteError(disparity, s.truth, area), 0.01);
    // Outside the area nothing changed.
    EXPECT_EQ(disparity.at<float>(5, 5), staircase(s.truth, 0.75).at<float>(5, 5));
}

// A facing surface at disparity `far` with a nearer one (`near`) right of column `stepX`, as a
// block's top against its plate: the right eye sees the near surface where it covers the far one,
// and the left pixels of the far surface it hides have no match (-1 in `truth`).
SlantedScene depthStep(double far, double near, int stepX) {
    const Texture texture(11);
    const cv::Size size(240, 120);
    SlantedScene s{cv::Mat(size, CV_32F), cv::Mat(size, CV_32F), cv::Mat(size, CV_32F)};
    for (int y = 0; y < size.height; ++y) {
        for (int x = 0; x < size.width; ++x) {
            s.left.at<float>(y, x) = static_cast<float>(texture(x, y));
            const bool onNear = x >= stepX;
            const bool hidden = !onNear && x - far >= stepX - near;
            s.truth.at<float>(y, x) = hidden ? -1.0f : static_cast<float>(onNear ? near : far);
            const double xl = x + near >= stepX ? x + near : x + far;
            s.right.at<float>(y, x) = static_cast<float>(texture(xl, y));
        }
    }
    return s;
}

TEST(SlantedRefinement, KeepsToOneSideOfADepthStep) {
    // A 4 px step (a block 60 mm high at 850 mm). Windows within their radius of it hold pixels of
    // the other surface; weighted by the matcher's disparities, they fit the centre's own.
    const SlantedScene s = depthStep(30.0, 34.0, 120);
    const cv::Rect nearStep(120 - 8, 20, 16, 80);
    auto errorBesideTheStep = [&](const SlantedRefinement& p) {
        cv::Mat disparity = s.truth.clone();
        refineSlanted(s.left, s.right, cv::Rect(40, 20, 160, 80), p, disparity);
        double sum = 0;
        int n = 0;
        for (int y = nearStep.y; y < nearStep.br().y; ++y)
            for (int x = nearStep.x; x < nearStep.br().x; ++x) {
                const float truth = s.truth.at<float>(y, x);
                if (truth < 0) continue;
                sum += std::abs(disparity.at<float>(y, x) - truth);
                ++n;
            }
        return sum / std::max(1, n);
    };
    EXPECT_LT(errorBesideTheStep(SlantedRefinement{}), 0.02);
    // Asking for half the window's support only (as on an object turned out of the view), the
    // weights alone keep the plane to its side.
    SlantedRefinement half;
    half.minSupportShare = kTurnedOutOfTheViewSupportShare;
    EXPECT_LT(errorBesideTheStep(half), 0.02);
    // Every pixel of the window weighing alike, the plane leans across the step.
    SlantedRefinement unweighted = half;
    unweighted.supportPx = 1e6;
    EXPECT_GT(errorBesideTheStep(unweighted), 0.05);
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
    // A staircase of whole pixels, as on an object turned out of the view.
    const SlantedScene s = slantedPlane(30.0, 0.0, -0.05, 1.15, -8.0);
    cv::Mat disparity = staircase(s.truth, 1.0);
    const cv::Rect area(40, 20, 160, 80);
    SlantedRefinement turned;
    turned.minSupportShare = kTurnedOutOfTheViewSupportShare;
    refineSlanted(s.left, s.right, area, turned, disparity);
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

TEST(SlantedRefinement, TheFastKernelAgreesWithItsReference) {
    // A staircase on a turned surface with noise on both eyes, a depth step, a blank band and
    // holes: every way a window ends (refined, too little support, blank, moved too far).
    SlantedScene s = slantedPlane(30.0, 0.01, 0.06, 1.1, -4.0);
    const SlantedScene step = depthStep(30.0, 34.0, 150);
    step.left.colRange(150, 240).copyTo(s.left.colRange(150, 240));
    step.right.colRange(120, 240).copyTo(s.right.colRange(120, 240));
    s.left(cv::Rect(60, 70, 40, 30)).setTo(200);
    s.right(cv::Rect(40, 70, 70, 30)).setTo(200);
    cv::RNG random(5);
    cv::Mat noise(s.left.size(), CV_32F);
    random.fill(noise, cv::RNG::NORMAL, 0.0, 0.4);
    s.left += noise;
    random.fill(noise, cv::RNG::NORMAL, 0.0, 0.4);
    s.right += noise;
    cv::Mat matched = staircase(s.truth, 0.5);
    matched(cv::Rect(100, 30, 6, 6)).setTo(-1.0f);
    matched(cv::Rect(180, 40, 10, 10)).setTo(37.0f);
    for (const double share : {SlantedRefinement{}.minSupportShare, kTurnedOutOfTheViewSupportShare}) {
        SlantedRefinement p;
        p.minSupportShare = share;
        cv::Mat fast = matched.clone(), reference = matched.clone();
        const cv::Rect area(10, 10, 220, 100);
        const SlantedRefinementCount nFast = refineSlanted(s.left, s.right, area, p, fast);
        const SlantedRefinementCount nReference = refineSlantedReference(s.left, s.right, area, p, reference);
        EXPECT_EQ(nFast.refined, nReference.refined) << share;
        EXPECT_EQ(nFast.kept, nReference.kept) << share;
        // Stopped early or refused at the end, the matcher's value stands either way: the fast
        // kernel sums in single precision, so a fit on the edge of the give-up test may go either way.
        EXPECT_NEAR(nFast.gaveUp, nReference.gaveUp, nReference.gaveUp / 100 + 1) << share;
        EXPECT_GT(nFast.refined, 1000) << share;
        EXPECT_GT(nFast.kept, 1000) << share;
        // A fit stops when its step is under 1e-3 px; the two may stop a step apart.
        const cv::Mat difference = cv::abs(fast - reference);
        double largest = 0;
        cv::minMaxLoc(difference, nullptr, &largest);
        EXPECT_LT(largest, 1e-3) << share;
        EXPECT_LE(cv::countNonZero(difference > 1e-4), nReference.refined / 1000) << share;
    }
}

TEST(SlantedRefinement, OnlyWhereAsked) {
    const SlantedScene s = slantedPlane(30.0, 0.01, 0.08, 1.0, 0.0);
    const cv::Mat matched = staircase(s.truth, 0.75);
    cv::Mat where(matched.size(), CV_8U, cv::Scalar(0));
    cv::circle(where, {120, 60}, 30, cv::Scalar(255), cv::FILLED);
    SlantedRefinement turned;
    turned.minSupportShare = kTurnedOutOfTheViewSupportShare;
    cv::Mat everywhere = matched.clone(), inCircle = matched.clone();
    refineSlanted(s.left, s.right, cv::Rect(20, 20, 200, 80), turned, everywhere);
    const SlantedRefinementCount n = refineSlanted(s.left, s.right, cv::Rect(20, 20, 200, 80), turned, inCircle, where);
    EXPECT_EQ(n.refined + n.kept, cv::countNonZero(where));
    // Inside, what the whole area gives (each window reads only the matcher's values); outside,
    // the matcher's.
    EXPECT_EQ(cv::countNonZero((inCircle != everywhere) & where), 0);
    EXPECT_EQ(cv::countNonZero((inCircle != matched) & ~where), 0);
    EXPECT_GT(cv::countNonZero((inCircle != matched) & where), n.refined * 9 / 10);
}

TEST(SlantedRefinement, GivesUpOnABlankWindowWithinItsFirstSteps) {
    // A faint ramp and noise (sky): the fit cannot tell a disparity there, and stops after its
    // first steps instead of running all of them; the matcher's values stand either way.
    cv::Mat left(120, 240, CV_32F), right(120, 240, CV_32F);
    for (int y = 0; y < left.rows; ++y)
        for (int x = 0; x < left.cols; ++x) left.at<float>(y, x) = right.at<float>(y, x) = 150.0f + 0.02f * x;
    cv::RNG random(9);
    cv::Mat noise(left.size(), CV_32F);
    random.fill(noise, cv::RNG::NORMAL, 0.0, 0.3);
    left += noise;
    random.fill(noise, cv::RNG::NORMAL, 0.0, 0.3);
    right += noise;
    const cv::Mat matched(left.size(), CV_32F, cv::Scalar(25.0f));
    const cv::Rect area(40, 20, 160, 80);
    SlantedRefinement stopping, running = stopping;
    running.giveUpFactor = 1e9;
    cv::Mat stopped = matched.clone(), ran = matched.clone();
    const SlantedRefinementCount n = refineSlanted(left, right, area, stopping, stopped);
    const SlantedRefinementCount all = refineSlanted(left, right, area, running, ran);
    EXPECT_EQ(n.refined, 0);
    EXPECT_EQ(all.refined, 0);
    EXPECT_EQ(all.gaveUp, 0);
    EXPECT_GT(n.gaveUp, n.kept / 2);
    EXPECT_EQ(cv::countNonZero(stopped != matched), 0);
    EXPECT_EQ(cv::countNonZero(ran != matched), 0);
}

}  // namespace
}  // namespace icewatch::volume
