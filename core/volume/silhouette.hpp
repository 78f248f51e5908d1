#pragma once

#include <opencv2/core.hpp>

#include "core/volume/height_grid.hpp"
#include "core/volume/registration.hpp"

namespace icewatch::volume {

// Ice standing out of the outline, seen by what it hides. Where the baseline saw no surface around
// the object (a featureless sky), the stereo matcher cannot measure a narrow bead there: its
// patches either find nothing to correlate or take the object's depth into the sky. But the
// camera does not move, and the background it saw beside the outline looks, pixel for pixel, the
// same in both captures unless something now stands in front of it: how far the ice reaches out
// of the outline is read off the picture.

// The background the current capture hides around the outline, and how the current capture's
// frame maps onto the baseline's. Empty `pixels`: nothing was looked at.
struct HiddenBackground {
    cv::Mat pixels;       // CV_8U per current left pixel
    RigidTransform toBaseline;
    // CV_8U per baseline left pixel: background in front of which nothing is measured, so that only
    // what it hides tells ice standing there: featureless (featurelessBackground, a sky), or
    // textured (a table) where the baseline measured it and the current capture measures nothing
    // in front of it.
    cv::Mat unread;
};

// Where the baseline saw featureless background beside the object (a sky, not a table): the
// pixels outside `object` (CV_8U) whose 9 x 9 neighbourhood, its background pixels alone, varies by
// less than minTextureGrey (standard deviation, on the image smoothed as the trackers' are). There the stereo matcher measures nothing, and
// the background hidden is the only sign of ice standing there. CV_8U, 255.
cv::Mat featurelessBackground(const cv::Mat& grey, const cv::Mat& object, double minTextureGrey);

// The pixels of `where` (CV_8U, left frame) whose grey in the current capture differs from the
// baseline's at the same pixel, scaled by the light's ratio between the captures (background_light.hpp),
// by more than max(minGrey, four robust standard deviations of that difference over `where`, most
// of which is background that did not change), in parts that hold a 3 x 3 block of such pixels
// (kept whole): what stands in front of the background hides a patch of it, not pixels alone.
// CV_8U, 255 where the background is hidden.
cv::Mat backgroundHidden(const cv::Mat& baselineGrey, const cv::Mat& currentGrey, const cv::Mat& where,
                         double lightRatio, double minGrey);

// The hidden background in front of which nothing was read (HiddenBackground::unread): the
// pixels of `hidden` the baseline measured as background (`baselineMeasured`) where the current
// capture measures nothing in front of them (`currentMeasured`), and all of the baseline's
// featureless background (`featureless`, may be empty). In front of a table, plain white ice
// standing out of the outline is read as the table behind it or not at all, so only what it hides
// tells it there, as in front of a sky. CV_8U, 255.
cv::Mat unreadBackground(const cv::Mat& hidden, const cv::Mat& baselineMeasured, const cv::Mat& currentMeasured,
                         const cv::Mat& featureless);

// The background left out of an outline drawn by hand (drawn_outline.hpp) beyond the ring the
// region is watched in: the drawn outline's pixels farther than ringPx from the region, both where
// the baseline had it and where the object's motion put it (CV_8U, all three frame-sized). That
// part was taken for background because its texture was as featureless as the background's; an
// object whose own texture is that faint loses its surface to it, and ice appearing there lies
// outside everything the chain measures (a block on a faint plate read -92 % and `ok`). What the
// current capture hides of it is told by backgroundHidden, as the ring's is.
cv::Mat leftOutBackground(const cv::Mat& drawn, const cv::Mat& region, const cv::Mat& regionInCurrent, int ringPx);

// What the background hidden in the current capture says of a grid on the baseline's plane: per
// node (placed at `heightMm` above the plane, moved into the current capture by the inverse of
// `toBaseline` and projected with `k`), whether its pixel in `hidden` is set. CV_8U.
cv::Mat hiddenOnGrid(const cv::Mat& hidden, const GridSpec& grid, const PlaneFrame& plane, const cv::Mat& heightMm,
                     const RigidTransform& toBaseline, const cv::Matx33d& k);

// How far the object's plane is turned out of the view, degrees: the angle between its normal and
// the camera's ray to its origin (0: facing the camera).
double viewObliquityDeg(const PlaneFrame& plane);

}  // namespace icewatch::volume
