#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <opencv2/core.hpp>

#include "core/calib/stereo_calibration.hpp"

namespace icewatch::synth {

enum class SceneKind {
    Blade,  // the seed paper's model blade: 0.82 m, chord 120 -> 32 mm, leading-edge ice + glaze
    Block,  // the seed paper's Table 5: a regular ice block on a flat plate
};

// "blade" or "block"; throws InvalidInput naming the bad value.
SceneKind parseSceneKind(std::string_view name);

inline constexpr int kMaxFrames = 256;

struct SceneSpec {
    SceneKind kind = SceneKind::Blade;
    double iceVolumeMm3 = 97609.0;
    std::uint32_t seed = 1;
    cv::Size frameSize{2560, 720};  // side-by-side, both eyes (a camera mode)
    double noiseSigma = 1.5;        // sensor noise, grey levels (0..255), Gaussian
    int jpegQuality = 90;           // MJPEG compression as the camera applies it, 1..100
    int frames = 1;                 // frames per capture (a burst), 1..kMaxFrames
    int supersampling = 3;          // samples per pixel and axis (anti-aliasing)
    double distanceMm = 850.0;      // camera to object
    double baselineMm = 60.0;
    double horizontalFovDeg = 80.0;
};

// The object's small rigid movement between the two captures (a parked blade is never exactly
// where it was), about the object's own origin, in the left camera frame.
struct RigidMotion {
    cv::Vec3d rotationDeg;
    cv::Vec3d translationMm;
};

struct SyntheticScene {
    calib::StereoCalibration calibration;
    // Each capture's frames exactly as the camera's MJPEG stream delivers them: the geometry is
    // rendered once per capture, every frame carries its own sensor noise and JPEG encoding.
    std::vector<std::vector<uchar>> beforeJpeg;
    std::vector<std::vector<uchar>> afterJpeg;
    cv::Mat before;  // the first frame of each capture, side-by-side BGR, decoded
    cv::Mat after;
    std::vector<cv::Point2d> roi;  // the object's outline in left-eye pixels (before capture)
    double iceVolumeMm3 = 0.0;     // exact, from the rendered geometry
    double maxIceThicknessMm = 0.0;
    RigidMotion motion;
    // Per left-eye pixel (CV_32F, stereo::kInvalidDisparity where the pixel is not wholly on the object): the true
    // disparity of each capture (f·B/Z averaged over the pixel's samples; the nominal
    // calibration's rectification is the identity) and the true ice thickness of the current one,
    // along the object's normal, mm. For measuring the matcher and the chain stage by stage.
    cv::Mat beforeDisparity;
    cv::Mat afterDisparity;
    cv::Mat afterIceMm;
};

// Renders both captures. Throws InvalidInput on a spec it cannot render (odd or tiny frame,
// negative volume, a block volume too large for its footprint, ...).
SyntheticScene renderScene(const SceneSpec& spec);

// Writes calibration.yaml, roi.json and truth.json into dir (created if needed), and for
// single-frame captures before.png and after.png; with truthMaps also truth_disparity_before.pfm,
// truth_disparity_after.pfm and truth_ice_mm.pfm (left eye). Captures of more than one frame are
// recordings, a format of drivers/ (a camera's output), so their caller writes them: icewatch synth
// does. Throws Error(kExitCantCreate) when a file cannot be written.
void writeScene(const SyntheticScene& scene, const SceneSpec& spec, const std::filesystem::path& dir,
                bool truthMaps = false);

}  // namespace icewatch::synth
