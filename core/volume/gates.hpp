#pragma once

#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "core/volume/chain.hpp"
#include "core/volume/motion_evidence.hpp"
#include "core/volume/parameters.hpp"
#include "core/volume/plane_clouds.hpp"
#include "core/volume/thickness_map.hpp"

namespace icewatch::volume {

// The estimate's gates: each looks at what one stage produced and says why a volume measured on it
// could not stand (the refusal's reason, written for whoever reads it on the tower), or nothing.
// VolumeChain::estimate calls them in this order, each as soon as what it judges is known.

// The baseline's region: there at all, and the object rather than the view.
std::optional<std::string> baselineRegionProblem(const Surface& baseline);

// Either capture's images (image_quality.hpp): exposure, contrast, clipping new in the current
// capture, and enough valid disparities in the region.
std::optional<std::string> capturesProblem(const Surface& baseline, const Surface& current, const Parameters& p);

// The baseline's plane seen edge-on: the region holds more than the object.
std::optional<std::string> edgeOnProblem(const PlaneFrame& plane);

// Texture too faint to rest the motion on the object alone, with no background to rest it on.
std::optional<std::string> faintTextureProblem(const Surface& baseline, const Surface& current,
                                               const MotionEstimate& motion, const Parameters& p);

// The thickness map covers none of the region, or its ice reaches the ring's outer edge.
std::optional<std::string> thicknessMapProblem(const ThicknessMap& map, const Parameters& p);
std::optional<std::string> ringEdgeProblem(const ThicknessMap& map, const Parameters& p);

// Too much of the ice's grid filled rather than measured.
std::optional<std::string> filledProblem(double filledPercent, const Parameters& p);

// Ice standing out of the outline of an object turned out of the view, read as if seen from the
// front; needs the result's integral and budget.
std::optional<std::string> outlineObliquityProblem(const ThicknessMap& map, const PlaneFrame& plane,
                                                   const VolumeResult& result, const Parameters& p);

// The matcher's surface where the ice may be, unchecked: fewer of the object's texture samples
// there found again in both eyes (`samples`, matcher_push.hpp) than a motion may rest on.
std::optional<std::string> uncheckedPushProblem(int samples, const Parameters& p);

// Ice on rows too plain for the matcher to tell its depth (row_texture.hpp); `unreadLost` where
// the texture was lost and stereo cannot read what hid it (lost_texture.hpp; may be empty). Sets
// result.faintIcePercent; reads result.thicknessImageMm.
std::optional<std::string> faintIceProblem(const Surface& baseline, const Surface& current, const PlaneFrame& plane,
                                           const RigidTransform& transform, const cv::Matx33d& k,
                                           std::optional<double> lightRatio, const cv::Mat& unreadLost,
                                           const Parameters& p, VolumeResult& result);

}  // namespace icewatch::volume
