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
// An image as the trackers read it, over a window of the frame: the smoothed grey for the integer
// search, and its cubic B-spline coefficients for the sub-pixel refinement, computed once per
// image (the exact recursive prefilter over whole rows and columns) rather than per patch.
struct TrackingImage {
    cv::Mat grey;      // CV_32FC1, Gaussian-smoothed (kTrackingSmoothingPx)
    cv::Mat spline;    // CV_32FC1, its cubic B-spline coefficients
    cv::Point origin;  // the frame pixel of grey(0, 0)

    bool empty() const { return grey.empty(); }
    cv::Rect frameRect() const { return {origin, grey.size()}; }
};

// Grey (any depth) seen over the frame window starting at `origin`, to the image trackPatch reads:
// Gaussian, σ = kTrackingSmoothingPx, and the spline's coefficients. The smoothing keeps the
// content the spline interpolates below Nyquist (0.7 % left there at 1 px) and the noise out of
// the integer search; more of it throws away the fine texture that places a patch: at 1.5 px the
// registrations of averaged blades scattered more (blades at 16 frames: 6 of 9 within 5 % at
// 1.5 px, 8 of 9 at 1 px). Less (0.7 px) helped the blades at 64 frames further but let the
// plate's registration lean towards a new block (blocks 0.5 % lower on average).
inline constexpr double kTrackingSmoothingPx = 1.0;
TrackingImage prepareForTracking(const cv::Mat& grey, cv::Point origin = {0, 0});

// The spline's value at a real frame position (integer positions give `grey` back); NaN where the
// spline is not exact (within the prefilter's margin of the window's edge).
double splineValueAt(const TrackingImage& image, cv::Point2d at);

// `at` and the shift are in frame pixels; a patch (with its search area) that does not lie inside
// both windows is not found.
PatchTrack trackPatch(const TrackingImage& from, const TrackingImage& to, cv::Point at, cv::Point2d prior,
                      const PatchTrackOptions& options = {});

}  // namespace icewatch::volume
