#pragma once

#include <opencv2/core.hpp>

namespace icewatch::volume {

// The matcher's disparities measured again on the averaged grey images, with a window that leans
// with the surface. The matcher's windows and scanlines assume a surface facing the camera: on a
// surface turned out of the view, or curved, over a weak texture, they return runs of one
// disparity (a staircase) and hold the object's lower edge at its neighbours' disparity, errors of
// up to a pixel and a half (ten millimetres at 850 mm). The ice changes the shape, so the steps fall
// elsewhere in the current capture than in the baseline: the volume takes their difference as ice,
// or as ice gone. A window whose right-eye footprint follows a plane, d + a·u + b·v, matches a
// slanted surface as well as a facing one; the plane's slopes, a gain and an offset (light that
// changed) are fitted with the disparity by Gauss-Newton, interpolating the right eye with a cubic
// B-spline, whose sub-pixel shifts are unbiased where the linear kernel's are not.
struct SlantedRefinement {
    int radius = 6;            // (2r+1)^2 window
    int iterations = 20;       // Gauss-Newton steps at most (a weak texture converges slowly)
    double maxChangePx = 2.0;  // further from the matcher's value: not the same surface, the matcher's stands
    // The fitted disparity's standard error (from the residual and the window's texture) above
    // which the window cannot tell (ice, sky, a blank patch): the matcher's value stands.
    double maxSigmaPx = 0.1;
    // Past its first giveUpAfterSteps steps, a fit whose standard error exceeds giveUpFactor times
    // maxSigmaPx stops there, refused as above: it seldom comes back under the limit (on a
    // 16-frame blade 24 of the 105 000 windows that passed had been there), and the sky around
    // the object, weakly textured, otherwise runs through every step or converges on a gain no
    // light gives.
    double giveUpFactor = 2.0;
    int giveUpAfterSteps = 2;
    // How far (px) the matcher's disparity may lie off the window's plane and still weigh half:
    // pixels across a depth step belong to another surface and weigh next to nothing.
    double supportPx = 0.5;
    // The window's weights must sum to this share of its pixels, or the matcher's value stands:
    // beside a depth step a plane fitted to one side is still pulled by the other's texture, and
    // the matcher's cross-shaped support does better (a rendered block's single-frame volume read
    // +26 % at a half, +5 % at this share, -2 % with the matcher alone). On an object turned out
    // of the view the matcher's own staircase keeps only part of the weight: there the chain asks
    // for kTurnedOutOfTheViewSupportShare.
    double minSupportShare = 0.85;
};

inline constexpr double kTurnedOutOfTheViewSupportShare = 0.5;

struct SlantedRefinementCount {
    int refined = 0;  // pixels whose disparity the slanted window replaced
    int kept = 0;     // valid pixels whose matcher's value stood
    int gaveUp = 0;   // of those, the fits stopped early (giveUpFactor)
};

// Refines the valid disparities (>= 0) of `disparity` (CV_32F, the size of the CV_32F grey
// images `left`, `right`) inside `area` and, when given, where `where` (CV_8U, the same size) is
// set; the others stay. Each pixel reads only the images and the matcher's disparities, never its
// neighbours' refined values, so the result does not depend on the order or the thread.
SlantedRefinementCount refineSlanted(const cv::Mat& left, const cv::Mat& right, const cv::Rect& area,
                                     const SlantedRefinement& parameters, cv::Mat& disparity,
                                     const cv::Mat& where = cv::Mat());
// The plain twin of refineSlanted (the support's plane through Eigen's products, the fit's sums
// pixel by pixel as the equations read): tests hold the two together.
SlantedRefinementCount refineSlantedReference(const cv::Mat& left, const cv::Mat& right, const cv::Rect& area,
                                              const SlantedRefinement& parameters, cv::Mat& disparity,
                                              const cv::Mat& where = cv::Mat());

}  // namespace icewatch::volume
