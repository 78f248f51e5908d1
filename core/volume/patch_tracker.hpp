#pragma once

#include <opencv2/core.hpp>

namespace icewatch::volume {

struct PatchTrackOptions {
    int radiusPx = 12;        // the patch is (2r+1)² pixels
    int searchPx = 6;         // integer search around the prior shift, ± this in x and y
    bool horizontalOnly = false;  // search only along the row (a rectified stereo pair)
    int iterations = 12;      // sub-pixel Gauss-Newton steps
    double convergedPx = 2e-3;  // a step smaller than this ends the refinement
};

struct PatchTrack {
    bool found = false;       // inside both images, a peak inside the search area, refinement converged
    cv::Point2d shift;        // where the patch is in `to` minus where it is in `from`, px
    cv::Matx22d covariance = cv::Matx22d::zeros();  // of the shift, px² (from the residual and the Hessian)
    double zncc = 0;          // zero-mean normalised correlation of the aligned patches
    double gain = 1;          // photometric fit to = gain · from + offset over the aligned patch
    double offset = 0;        // grey levels
    double offsetSigma = 0;   // its 1-σ, grey levels
    double residualSigma = 0; // rms of to - (gain · from + offset), grey levels
    double textureSigma = 0;  // standard deviation of the `from` patch, grey levels
    double meanFrom = 0;      // mean grey level of the `from` patch
    double brightnessRatio = 1;  // mean of the aligned `to` patch over that of `from`
};

// Finds the patch of `from` centred on the integer pixel `at` again in `to`, near `at + prior`.
// Both images are CV_32FC1 grey (0..255, e.g. the float average of many frames).
//
// First the integer shift with the best zero-mean normalised correlation in the search area, then
// a symmetric sub-pixel refinement: `from` is resampled at -δ/2 and `to` at +δ/2 around the
// integer shift with the same prefiltered cubic B-spline, so the interpolator treats both alike
// and its phase error stays below a thousandth of a pixel on the smoothed images
// (prepareForTracking, which takes noise out as well). A gain, an offset and a gain ramp across
// the patch are fitted with the shift at every step, so neither a change of light between the
// captures nor a surface turning against it moves the shift; the gain and offset are reported
// because a layer of ice changes them in a way light does not (light scales radiance: the offset
// stays zero).
// Grey (any depth) to the float image trackPatch reads: Gaussian, σ = kTrackingSmoothingPx.
inline constexpr double kTrackingSmoothingPx = 1.5;
cv::Mat prepareForTracking(const cv::Mat& grey);

PatchTrack trackPatch(const cv::Mat& from, const cv::Mat& to, cv::Point at, cv::Point2d prior,
                      const PatchTrackOptions& options = {});

}  // namespace icewatch::volume
