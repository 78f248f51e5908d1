#pragma once

#include <vector>

#include <opencv2/core.hpp>

namespace icewatch::volume {

struct PlaneFrame;

struct RigidTransform {
    cv::Matx33d rotation = cv::Matx33d::eye();
    cv::Vec3d translation{0, 0, 0};
    cv::Vec3d apply(const cv::Vec3d& p) const { return rotation * p + translation; }
};

// How much of the object the points that fixed the registration span: each of the object's two
// in-plane axes is cut into ten bins over the region's extent, a bin counts when the support holds
// at least a third of the region's samples in it, and the smaller share of counted bins is
// returned. A tilt fitted on a patch at one end is extrapolated over the rest, its error growing
// with the distance: support over a seventh of a blade's span, as when ice hides the texture
// everywhere but at the root, turned a 97 609 mm³ blade into 680 000 mm³. A few scattered texture
// patches do not make a support either: the matcher's errors are correlated over centimetres.
// `samples`: current points, moved by `transform` into the baseline and put in `plane`;
// `support`: one flag per sample (empty: all). Percent, 0 with fewer than 2 samples.
double supportSpanPercent(const std::vector<cv::Vec3d>& samples, const std::vector<std::uint8_t>& support,
                          const RigidTransform& transform, const PlaneFrame& plane);

// A baseline pixel of the object, put on the baseline's plane and moved by the registration
// (`toBaseline`, current -> baseline) into the current capture: where the camera `k` sees it there,
// and how far from the camera it is (mm). What a baseline outline becomes in the current capture.
// NaN, place and depth, for a pixel whose ray meets the plane behind the camera or never.
struct PixelInCurrent {
    cv::Point2d at;
    double depthMm = 0;
};
PixelInCurrent planePixelInCurrent(cv::Point2d baselinePx, const PlaneFrame& plane, const RigidTransform& toBaseline,
                                   const cv::Matx33d& k);

}  // namespace icewatch::volume
