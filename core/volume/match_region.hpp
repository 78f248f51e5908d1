#pragma once

#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "core/stereo/matcher.hpp"
#include "core/volume/parameters.hpp"

namespace icewatch::volume {

// Where a capture after the baseline is matched: a box of rectified left pixels and a band of
// disparities, both taken from the baseline (match_region.cpp explains the margins).
struct MatchRegion {
    cv::Rect regionBox;           // the baseline region's bounding box (rectified left pixels)
    cv::Rect box;                 // rectified left pixels matched; the disparity is invalid outside
    stereo::DisparityRange band;  // disparities searched
    int marginPx = 0;             // how far the box reaches beyond the region's bounding box
    int reachPx = 0;              // of that, what the matcher's own windows need (crop edge effects)

    bool empty() const { return box.empty(); }
    // How far around the region its surface is read: the motion the registration accepts, the
    // trackers' patches and the ring where ice may stand out of the outline (the margin less the
    // matcher's reach, which only the matching needs).
    int surfaceMarginPx() const { return marginPx - reachPx; }
};

// Pixels around a pixel whose values change its disparity: the cross arms of aggregation and the
// region voting that follows it, the Census window and the sub-pixel refinement (SGBM: its block).
// The scanlines reach the whole image; their effect decays within a few arm lengths (tested).
int matcherReachPx(stereo::Method method, const stereo::Parameters& stereoParameters);

// The region and band for every later capture, from the baseline's disparity and region
// (rectified left pixels, CV_32F and CV_8U). q: the calibration's reprojection matrix; focalPx its
// rectified focal length. Throws InvalidInput when the region holds no valid disparity.
MatchRegion matchRegionFromBaseline(const cv::Mat& disparity, const cv::Mat& roi, const cv::Matx44d& q,
                                    double focalPx, const Parameters& parameters, int reachPx);

// A baseline whose region is known before it is matched (a configured outline) is matched in that
// region too, in two passes: first the window coarseWindow gives, reduced coarseFactor times and
// over every disparity, then at full resolution in the region and band this gives from the first
// pass's disparities (scaled back to full pixels and placed in a frame-sized map). The whole frame
// over every disparity would take about 2.4 GB at 1920x1080 per eye.
inline constexpr int kCoarseFactor = 2;
cv::Rect coarseWindow(const cv::Mat& roi, int maxDisparity, int reachPx, int coarseFactor);
MatchRegion baselineRegionFromCoarse(const cv::Mat& coarseDisparity, const cv::Mat& roi, const cv::Matx44d& q,
                                     double focalPx, const Parameters& parameters, int reachPx, int coarseFactor);

// The box the matcher is given: the region's box widened to the left by the band's largest
// disparity, so that every pixel of the box has its candidates in the right eye.
cv::Rect matcherWindow(const MatchRegion& region, cv::Size imageSize);

// How alike two grey images are inside a mask (normalised cross-correlation, -1 .. 1; 0 when
// either is flat there).
double maskedCorrelation(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask);

// Why a capture matched in `region` cannot be measured: the object moved (shift, rectified left
// pixels, against the baseline) so far that its region comes within the matcher's reach of the
// matched box's cut edge. nullopt when it can (always for an empty region: the full frame).
std::optional<std::string> regionProblem(const MatchRegion& region, cv::Size imageSize, cv::Point2d shiftPx);

}  // namespace icewatch::volume
