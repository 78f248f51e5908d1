#pragma once

#include <opencv2/core.hpp>

#include "core/volume/parameters.hpp"
#include "core/volume/texture_tracks.hpp"

namespace icewatch::volume {

// Ice beyond the outline. Ice grows on the leading edge, and the leading edge is the blade's
// outline as the camera sees it: a bead or a horn there stands out of the clean outline, against
// the sky or the table, where the baseline has no surface to difference it with. It is looked for
// in a ring around the baseline's outline and measured from the surface it grows from.

// How far a patch of measurableRing reaches: that far from the featureless sky nothing is measured.
constexpr int kRingPatchRadiusPx = 4;

// The ring's width in pixels: outline_growth_mm at the object's depth.
int outlineGrowthPx(const Parameters& parameters, double focalPx, double depthMm);

// `region` (CV_8U) grown by growthPx, less the region grown by skipPx: the first pixels outside
// the outline mix the object's depths with what is behind it, as the edge margin inside does
// (and a surface that only stands out of the outline by a pixel's rounding is not beyond it).
// All 0 for growthPx 0.
cv::Mat outlineRing(const cv::Mat& region, int growthPx, int skipPx = 0);

// The ring's pixels whose disparity is a measurement: the left image's patch (9 x 9 px) there is
// textured (standard deviation at least outline_min_texture_grey) and found again in the right
// image at that disparity (zero-mean normalised correlation at least outline_min_correlation),
// less the 4 px by which such a patch reaches past a silhouette into the pixels that failed. The
// matcher fills featureless sky with the disparities of the object beside it, and the sky's noise
// does not correlate between the eyes. CV_8U.
cv::Mat measurableRing(const RectifiedCapture& capture, const cv::Mat& ring, const Parameters& parameters);

// Which grid nodes outside the region hold ice standing out of it. `riseMm` (CV_64F, NaN where
// not measured) is the current surface's height above the surface the ice grows from at each
// node outside the region; `inside` (CV_8U) the region's nodes. A connected part of the rise above
// floorMm (0, or the rise's noise where it is a difference of two measured surfaces) is ice when it touches the region (ice grows from the object; the sky, a bird or the table
// do not touch it from above) and rises somewhere by min_rise_mm, well above the depth noise: it
// is measured down to where it meets the surface, not cut at the threshold. The ring leaves a gap
// of up to gapNodes next to the region (outlineRing's skip): a part within it touches, and the
// gap's nodes between the two are ice too (their thickness is then the nearest measured). CV_8U,
// 255 on ice.
cv::Mat iceBeyondOutline(const cv::Mat& riseMm, const cv::Mat& inside, double minRiseMm, int gapNodes = 0,
                         double floorMm = 0.0);

// How many nodes of the ring's outer edge (`ringEdge`, CV_8U) ice beyond the outline reaches:
// ice that may reach farther than the chain looks (icicles hanging from an edge, a long horn).
// Counted are the parts of `beyond` whose `thicknessMm` (CV_64F) is at least twice minRiseMm, and
// the `tapered` nodes (may be empty: seen only by the background they hide), that stand so all the
// way from the outline: within gapNodes (unmeasured) of `inside`.
int iceAtRingEdge(const cv::Mat& beyond, const cv::Mat& tapered, const cv::Mat& thicknessMm, const cv::Mat& inside,
                  const cv::Mat& ringEdge, double minRiseMm, int gapNodes);

// Ice standing out of the outline where nothing under it could be measured, seen only by the
// background it hides (`hidden`, per node, silhouette.hpp): as high on the outline as the ice on
// the region's nearest nodes (`edgeThicknessMm`, per node), tapering to nothing where the
// background shows again, as a rounded bead does: (1 - t^2) of that height, t from the outline
// (0) to the hidden part's far edge (1). A part that does not touch the region is not ice, nor is
// one whose ice on the outline is under minThicknessMm (a cloud passing behind a clean edge hides
// the background too). Next to the outline the background could not be compared (the baseline
// showed the object there): nodes between the region and a hidden part, up to gapNodes wide,
// stand too. Writes the thickness into `thickness` (CV_64F) on the nodes it returns (CV_8U, 255).
// With `thinMm` (CV_64F, the size of `inside`), the parts that stand but whose outline read under
// minThicknessMm get there the thickness they would have with minThicknessMm on the outline, and
// NaN elsewhere: not ice, but the least that would have counted, should the outline read too thin.
cv::Mat taperedIce(const cv::Mat& hidden, const cv::Mat& inside, const cv::Mat& edgeThicknessMm, double minThicknessMm,
                   int gapNodes, cv::Mat& thickness, cv::Mat* thinMm = nullptr);

// How deep ice seen only by its silhouette may be, towards the camera: no deeper than it is wide
// across. Ice standing free of the object is about round in section (an icicle, a bead, a horn);
// the taper above takes it as no higher than the ice on the outline it grows from, and an
// icicle's root stands higher than the runback band it hangs from (rendered, in a 200 mm ring,
// read -58 % and `ok` outside its uncertainty). At each node of `parts` (CV_8U) the diameter of
// the largest disc inside its part that covers the node, mm (`cellMm` the node spacing); a part
// ends half a node beyond its last node. CV_64F, 0 outside the parts.
cv::Mat widthAcrossMm(const cv::Mat& parts, double cellMm);

}  // namespace icewatch::volume
