#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "core/calib/stereo_calibration.hpp"
#include "core/synth/rasterizer.hpp"
#include "core/synth/shading.hpp"

namespace icewatch::synth {

// What the left eye sees of the geometry, per pixel: true disparity and ice thickness.
struct EyeTruth {
    cv::Mat disparity;
    cv::Mat iceMm;
};

// The light one eye (pinhole at (centreXMm, 0, 0) with the calibration's left intrinsics) receives
// from the meshes, CV_32F 0..1 at the calibration's image size: supersampling² samples per pixel,
// box-filtered. With truth, also the truth maps for a camera of truthBaselineMm.
cv::Mat renderEye(const std::vector<Mesh>& meshes, const Shading& shading, const calib::StereoCalibration& calibration,
                  double centreXMm, int supersampling, double truthBaselineMm = 0, EyeTruth* truth = nullptr);

}  // namespace icewatch::synth
