#pragma once

#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "core/volume/height_grid.hpp"
#include "core/volume/parameters.hpp"
#include "core/volume/plane_clouds.hpp"
#include "core/volume/silhouette.hpp"

namespace icewatch::volume {

// The ice thickness on a regular grid over the region, on the baseline's plane.
struct ThicknessMap {
    GridSpec grid;
    cv::Mat thickness;       // CV_64F mm: current minus baseline where ice may be, 0 elsewhere inside, NaN outside
    cv::Mat baselineHeight;  // CV_64F mm, filled from the nearest node everywhere (the nodes' place on the object)
    cv::Mat inside;          // CV_8U per node: within the region's outline
    cv::Mat onIce;           // CV_8U per node: within the ice mask, or ice beyond the outline
    cv::Mat beyond;          // CV_8U per node: ice standing out of the outline (beyond_outline.hpp)
    cv::Mat tapered;         // CV_8U per node: the part of `beyond` seen only by the background it hides
    cv::Mat thinBeyondMm;    // CV_64F per node: what hides the background where the outline read too thin for
                             // ice (not counted), at the least that would have counted; NaN elsewhere
    cv::Mat fringe;          // CV_8U per node: ice inside the outline within outline_fringe_px of `tapered`
                             // or of `thinBeyondMm`
    cv::Mat seenThrough;     // CV_8U per node: ice inside the outline the object's texture was seen
                             // through (kSeenThrough) or glimpsed through (kGlimpsedThrough), as
                             // seen_through.hpp says; empty when there was none
    // CV_64F per node: how far the thickness stands above its least, where a band the camera does
    // not see along its line of sight (behind a block's far edge, under a horn seen at an angle) was
    // bridged by the interpolation in either capture; 0 elsewhere. The hidden band may be as low as
    // the far surface or as high as the near one: the bridge is the middle. In front of an outline
    // that stands off its background (outline_standoff_mm), ice is measured from halfway down to
    // the background, and half that band is its hidden part.
    cv::Mat hiddenMm;
    // CV_8U per node: the ring's outer edge, its last pixels away from the outline (kRingEdgePx).
    // Ice beyond the outline found there reaches as far as the chain looks, and may reach farther
    // (icicles hanging from an edge): beyondAtRingEdgeNodes counts its nodes, those seen by the
    // background they hide or rising twice the least that counts as ice, all the way from the
    // outline (iceAtRingEdge).
    cv::Mat ringEdge;
    int beyondAtRingEdgeNodes = 0;
    int insideNodes = 0, iceNodes = 0, beyondNodes = 0, taperedNodes = 0;
    int filledNodes = 0;     // ice nodes without a measurement, filled from the nearest
};

// The grid over the region: the outline of `roi` (its outer contours) put on the plane through
// the rays of its pixels, so that the grid holds all the region shows of the plane. No grid when
// the outline has no measurable extent on the plane: a pixel whose ray meets it behind the camera
// or never, or a grid of too many nodes (a plane seen nearly edge-on). The scene is not malformed
// then, the outline is: `problem` says which pixel or how many nodes, for the refusal.
using OutlineGrid = GridOrProblem;
OutlineGrid outlineGrid(const cv::Mat& roi, const PlaneFrame& plane, const cv::Matx33d& k, double cellMm);

// On `grid` (outlineGrid of the region and its ring), interpolates both clouds linearly
// (height_grid.hpp) and differences them where `possibleIce` (per left baseline pixel) says ice
// may be; the surface that unchanged texture vouched for is clean, 0, so neither its noise nor the
// registration's error there is integrated. A node is placed in the image at the baseline's
// height above the plane (the plane alone would misplace nodes by the blade's camber). `k`: the
// rectified left camera matrix.
//
// Beyond the outline, in `ring` (per left baseline pixel, around `roi`), the current surface is
// measured from what the baseline saw there (a table, more of a plate than the outline drawn on
// it, the matcher's fringe) or, where it saw sky, from the surface the ice grows from, the
// outline's nearest (baselineHeight, filled); it counts where iceBeyondOutline finds ice rising
// outline_ice_min_mm and four times the noise of the rise where both captures saw a surface.
// Where the baseline saw no surface and the current capture hides the background (`hidden`,
// silhouette.hpp), the ice is tapered from the outline's (taperedIce) rather than measured from a
// footing nobody saw. `seenThrough` (per left baseline pixel, may be empty) marks the ice nodes
// where the object's texture was seen through the ice.
ThicknessMap thicknessMap(const GridSpec& grid, const PlaneClouds& clouds, const cv::Mat& roi, const cv::Mat& ring,
                          const cv::Mat& possibleIce, const PlaneFrame& plane, const cv::Matx33d& k,
                          const Parameters& parameters, const HiddenBackground& hidden = {},
                          const cv::Mat& seenThrough = {});

// For people: a grid map (NaN where none) where it lies in the current left image, inside
// `outline`. Each pixel's ray, moved into the baseline's frame, meets the baseline's plane at the
// grid node it shows (the plane alone misplaces it by the camber, less than a node at this scale).
// CV_32F, NaN outside.
cv::Mat thicknessInImage(const cv::Mat& thickness, const GridSpec& grid, const PlaneFrame& plane,
                         const RigidTransform& toBaseline, const cv::Matx33d& kInv, const cv::Mat& outline);

// The thickness map summed up for the report.
struct IceSummary {
    double volumeMm3 = 0;
    double areaMm2 = 0;          // of the region on the plane
    double iceAreaMm2 = 0;       // of the ice mask on the plane, and of the ice beyond the outline
    double beyondOutlineMm3 = 0, beyondOutlineAreaMm2 = 0;  // the part standing out of the outline
    double meanThicknessMm = 0;  // volume over the region's area: what the alarms compare, steady
                                 // however far the ice mask reaches
    double maxThicknessMm = 0;   // of the thickness averaged over 5 × 5 nodes (one node is noise)
    cv::Mat smoothedMm;          // that averaged map (CV_64F, NaN outside the region): what people see
};
IceSummary summarise(const ThicknessMap& map, Integration method);

}  // namespace icewatch::volume
