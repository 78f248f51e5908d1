#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "core/volume/height_grid.hpp"
#include "core/volume/parameters.hpp"
#include "core/volume/registration.hpp"

namespace icewatch::volume {

// Both captures' points in the baseline's plane frame (u, v, h per left pixel, CV_64FC3, NaN where
// there is none), the current capture moved onto the baseline, the k-NN filter's strays removed.
// Both maps cover `box` only, the frame's pixels that hold a point of either capture: the region,
// not the frame (100 MB less at 3840x1080), and the lattice the grid interpolates is the same.
struct PlaneClouds {
    cv::Rect box;  // in the frame; the maps' pixel (0, 0) is box.tl()
    cv::Mat baseline;
    cv::Mat baselineRing;  // what the baseline saw around its outline (beyond_outline.hpp)
    cv::Mat current;
    cv::Mat currentRing;   // the current points around the outline, apart: each side is measured by its own
    int currentPoints = 0;
};

// The baseline's half of the above, which depends on the baseline alone (a daemon works it out
// once per baseline, BaselineModel): its points in the plane frame, where they lie, their height
// range and the k-NN filter's verdict on each.
struct BaselineCloud {
    std::vector<cv::Point3d> points;  // u, v, h
    std::vector<cv::Point> pixels;
    std::vector<std::uint8_t> keep;   // 1: kept by the k-NN filter
    double lowestMm = 0, highestMm = 0;
};

// `measured`: the baseline pixels that count (the region, eroded by the edge margin, with a
// point).
BaselineCloud baselineCloud(const cv::Mat& baselinePoints, const cv::Mat& measured, const PlaneFrame& plane,
                            const Parameters& parameters);

// `currentOutline`: the region as the object stands in the current capture; `currentRing`: the
// ring around it where ice standing out of it is looked for. A current point far behind the baseline's lowest point is background, one above its highest
// point by more than max_thickness_mm is sky or a stray: neither is the object. `baselineRing`:
// the baseline's points in the ring around its own outline.
PlaneClouds planeClouds(const BaselineCloud& baseline, const BaselineCloud& baselineRing, const cv::Mat& currentPoints,
                        const cv::Mat& currentOutline, const cv::Mat& currentRing,
                        const PlaneFrame& plane, const RigidTransform& toBaseline, const Parameters& parameters);

// The baseline's outline as the object stands in the current capture: every outline pixel is put
// on the baseline's plane, moved back by the registration and projected; then eroded by the edge
// margin, where depths mix.
cv::Mat outlineInCurrent(const cv::Mat& roi, const PlaneFrame& plane, const RigidTransform& toBaseline,
                         const cv::Matx34d& projection, int edgeMarginPx);

}  // namespace icewatch::volume
