#pragma once
// What the estimate needs of the baseline alone, worked out once per baseline: the daemon keeps
// the baseline's surface and estimates against it every cycle, and none of this changes between
// cycles. The numbers are those an estimate would work out itself, to the last bit.

#include <optional>

#include <opencv2/core.hpp>

#include "core/volume/height_grid.hpp"
#include "core/volume/parameters.hpp"
#include "core/volume/plane_clouds.hpp"
#include "core/volume/texture_tracks.hpp"

namespace icewatch::volume {

struct BaselineModel {
    // Of the region eroded by the edge margin (depths mix at the outline), the pixels where the
    // baseline has a point.
    int measuredPoints = 0;
    // The rest only when there are at least min_points of them (the estimate refuses otherwise).
    PlaneFrame plane;         // fitted to the measured points: the frame thickness is measured in
    BaselineCloud cloud;      // those points on the plane, with the k-NN filter's verdicts
    BaselineSamples samples;  // the trackers' samples and the baseline's own stereo tracks
    // The ring around the outline where ice beyond it is looked for (beyond_outline.hpp): its
    // width, and what the baseline saw there (the outline's own fringe, a table, nothing).
    int ringPx = 0;
    cv::Mat ringMask;  // CV_8U: the ring itself, from edge_margin_px to ringPx outside the region
    cv::Mat ringMeasurable;  // CV_8U: the ring's pixels whose disparity is a measurement (measurableRing)
    BaselineCloud ring;
    // What the current capture's background is compared against (silhouette.hpp): the region grown
    // by 2 px, which the comparisons leave out, and the featureless background beside it.
    cv::Mat objectGrown;
    cv::Mat featureless;
    // How blurred the baseline is, read off its outline or the object's edge around it
    // (objectBlurPx, edge_blur.hpp); none where neither stands out of its background.
    std::optional<double> blurPx;
};

// `roi`: the region (CV_8U); `points`: the baseline's points (CV_32FC3, NaN where none);
// `capture`: its tracking images and disparity; `leftGrey`: its left image (CV_32F, frame-sized);
// `focalPx`: the rectified focal length.
BaselineModel buildBaselineModel(const cv::Mat& roi, const cv::Mat& points, const RectifiedCapture& capture,
                                 const cv::Mat& leftGrey, double focalPx, const Parameters& parameters);

// The plane buildBaselineModel fits, alone (none below min_points): what a baseline's slanted
// windows need to know before its model is built on them.
std::optional<PlaneFrame> baselinePlane(const cv::Mat& roi, const cv::Mat& points, const Parameters& parameters);

// The texture trackers' options from the volume parameters.
TextureTrackOptions textureTrackOptions(const Parameters& parameters);

}  // namespace icewatch::volume
