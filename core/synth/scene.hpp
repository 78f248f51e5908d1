#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <opencv2/core.hpp>

#include "core/calib/stereo_calibration.hpp"
#include "core/synth/look.hpp"

namespace icewatch::synth {

enum class SceneKind {
    Blade,  // the seed paper's model blade: 0.82 m, chord 120 -> 32 mm
    Block,  // the seed paper's Table 5: a regular ice block on a flat plate
};

// The blade's ice (blade.cpp says how each is shaped).
enum class IceKind {
    LeadingEdge,  // accretion along the leading edge, growing towards the tip, plus a thin glaze
    GlazeAll,     // a thin translucent glaze over the whole visible surface
    Patches,      // a few opaque, rough rime patches anywhere on the blade
    Bead,         // a narrow bead on the leading edge, a few mm to a few cm wide, standing out of
                  // the outline the camera sees
    BeadGlaze,    // the same bead over a thin glaze across the whole visible surface
    Ridges,       // a few narrow, steep ridges along the span behind the leading edge (runback ice)
    Shed,         // sheets of one thickness left after part of the ice shed, each ending in a sharp step
    Icicles,      // icicles hanging out of the trailing edge, far beyond the outline, over a runback
                  // band along it
};

// How the object moved between the captures.
enum class MotionKind {
    None,   // the identical pose (a blade held in a rig, a camera that did not move)
    Small,  // a parked blade is never exactly where it was: up to 3 mm and 0.3° (block 1 mm, 0.1°)
    Large,  // parked at another pitch, or bent by another wind: up to 15 mm and 1.5° (block 5 mm, 0.5°)
};

// How the blade's surface shows through its ice where the ice lets it (thin, translucent or clear).
enum class IceOptics {
    Painted,     // on the ice's outer surface, as a renderer that blends colours on one surface draws it
    Refractive,  // where it is, under the ice, seen along rays bent by the ice (n = 1.31): a stereo
                 // camera sees it raised by about a quarter of the ice's thickness, not by all of it
};

// What lies behind the object.
enum class Background {
    Sky,    // overcast, almost featureless
    Table,  // a textured tabletop the object lies on (it moves with the object)
};

// How the camera, or the renderer, turns light into grey levels.
enum class ToneCurve {
    Linear,  // grey proportional to light, as a camera's raw data
    Gamma,   // a power law, 1/2.2 as sRGB's and a UVC camera's: a change of light scales every grey
             // level by one factor, but by less than the light changed (0.85 -> 0.93)
    Filmic,  // a toe, a compressed shoulder and sRGB's gamma, as renderers and cameras' processors
             // make pictures look: a change of light changes bright and dark surfaces unequally
};

// Each parses the name the command line and truth.json use; throws InvalidInput naming the bad value.
SceneKind parseSceneKind(std::string_view name);
IceKind parseIceKind(std::string_view name);
MotionKind parseMotionKind(std::string_view name);
Background parseBackground(std::string_view name);
IceOptics parseIceOptics(std::string_view name);
ToneCurve parseToneCurve(std::string_view name);
std::string sceneKindName(SceneKind kind);
std::string iceKindName(IceKind kind);
std::string motionKindName(MotionKind kind);
std::string backgroundName(Background background);
std::string iceOpticsName(IceOptics optics);
std::string toneCurveName(ToneCurve curve);

inline constexpr int kMaxFrames = 256;
inline constexpr double kMinLightChange = 0.2;
inline constexpr double kMaxLightChange = 3.0;
inline constexpr double kMaxRollDeg = 180.0;
inline constexpr double kMinDistanceMm = 600.0;
inline constexpr double kMaxDistanceMm = 1500.0;
inline constexpr double kMaxLightTurnDeg = 60.0;
inline constexpr double kMaxSunChange = 3.0;
inline constexpr double kMaxSunAngleDeg = 80.0;
inline constexpr double kMaxCloudDrift = 0.5;
inline constexpr double kMaxGloss = 1.0;
inline constexpr double kMaxTiltDeg = 45.0;
inline constexpr double kMaxTableGapMm = 100.0;
inline constexpr double kMinIcicleLength = 0.1;
inline constexpr double kMaxIcicleLength = 2.0;
inline constexpr double kMaxBlurPx = 5.0;
// The look's overrides (SceneSpec): what another renderer, or another blade, may show.
inline constexpr double kMinTextureContrast = 0.005, kMaxTextureContrast = 0.3;
inline constexpr double kMinTextureFeatureMm = 0.5, kMaxTextureFeatureMm = 50.0;
inline constexpr double kMinIceWhiteness = 0.4, kMaxIceWhiteness = 1.0;

struct SceneSpec {
    SceneKind kind = SceneKind::Blade;
    double iceVolumeMm3 = 97609.0;
    std::uint32_t seed = 1;  // pose, motion, look, ice placement and noise
    cv::Size frameSize{2560, 720};  // side-by-side, both eyes (a camera mode)
    double noiseSigma = 1.5;        // sensor noise, grey levels (0..255), Gaussian
    // Another draw of the sensor noise (and so of each frame's JPEG encoding) for the same scene:
    // 0 is the seed's own; any other number changes nothing but the noise, so the noise's share of
    // an error can be measured on a scene whose every other part stays.
    std::uint32_t noiseDraw = 0;
    int jpegQuality = 90;           // MJPEG compression as the camera applies it, 1..100
    // The lens's blur, the sigma of a Gaussian on each eye in px (0: as sharp as the pixels),
    // and the tone curve: what another camera or renderer does to the light before the sensor's noise.
    double blurPx = 0.0;
    ToneCurve toneCurve = ToneCurve::Linear;
    int frames = 1;                 // frames per capture (a burst), 1..kMaxFrames
    int supersampling = 3;          // samples per pixel and axis (anti-aliasing)
    IceKind ice = IceKind::LeadingEdge;  // the blade's; a block scene's ice is the block
    MotionKind motion = MotionKind::Small;
    Background background = Background::Sky;
    IceOptics optics = IceOptics::Painted;
    double lightChange = 1.0;  // the current capture's illumination over the baseline's
    double lightTurnDeg = 0.0; // the current capture's light direction turned by this (the sun moved)
    // The current capture's direct light (the sun, a rig's lamps) over the baseline's, while the
    // light of the sky (the ambient share, and the sky seen behind the object) stays as it was: the
    // sun went behind a cloud (under 1) or came out (over 1). Unlike lightChange, a surface
    // facing the sun changes more than one facing away, and the sky not at all.
    double sunChange = 1.0;
    // The light's angle from the view axis, degrees (0: the seed's, 9-44°; up to 80: a low sun
    // from the side, half the blade in its own shade and long shadows), about the seed's azimuth.
    double sunAngleDeg = 0.0;
    double distanceMm = 850.0;  // camera to object
    double rollDeg = 0.0;       // the object turned by this about the view axis (in the image)
    // The object turned out of the view: about the image's horizontal axis (tilt: seen from above
    // or below, its chord foreshortened) and its vertical axis (swing: one end nearer than the other).
    double tiltDeg = 0.0;
    double swingDeg = 0.0;
    // Clouds drift behind the object by this share of the image's width between the captures
    // (0: an even overcast without clouds), where the sky shows.
    double cloudDrift = 0.0;
    // Wet ice mirrors this much of the light towards the eye at its highlight's peak (0: matte);
    // the blade's coat a third of it (highlight.hpp).
    double gloss = 0.0;
    // The sun casts shadows (shadow.hpp): the object darkens the table or the plate beside it, and
    // ice standing out darkens the surface behind it. Off: every surface sees the light, as a
    // renderer without shadow rays draws it.
    bool shadows = false;
    // The blade rests this far above the table (mm): on trestles, or a whole airfoil lying on its
    // lower surface, whose edges stand off the table by half its thickness. The outline is then a
    // step down to the table, and a lit blade's shadow falls beside it. 0: it lies on the table.
    double tableGapMm = 0.0;
    // Glaze-all grown along the surface's normals, as ice forms: it wraps the leading and the
    // trailing edge and stands out of the clean outline by its thickness there (a half-round of
    // clear ice along each edge, what lies behind it showing through). Off: a height field over the
    // planform that ends at the outline.
    bool iceOverEdges = false;
    // Icicles' lengths times this (icicleFront): 1 hangs them 3-7 times their size, far beyond the
    // ring the chain watches; 0.25 makes them stubby, holding as much ice within a few tens of mm.
    double icicleLength = 1.0;
    // The look the seed draws (look.hpp), overridden where set (0: the seed's): the composite's
    // texture amplitude (the seed's 0.027-0.05) and the size of its coarsest features (4.5-8.5 mm),
    // and the albedo of ice thick enough to hide what is under it (0.82-0.93).
    double textureContrast = 0.0;
    double textureFeatureMm = 0.0;
    double iceWhiteness = 0.0;
    double baselineMm = 60.0;
    double horizontalFovDeg = 80.0;
};

// The object's small rigid movement between the two captures (a parked blade is never exactly
// where it was), about the object's own origin, in the left camera frame.
// The object's motion between the captures: p_after = R·(p_before − pivot) + pivot + translation,
// R the rotation vector rotationDeg (degrees), in the left camera's frame, mm.
struct RigidMotion {
    cv::Vec3d rotationDeg;
    cv::Vec3d translationMm;
    cv::Vec3d pivotMm;  // the object frame's origin in the baseline capture
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
    Look look;
    // Per left-eye pixel (CV_32F, stereo::kInvalidDisparity where any of the pixel's samples sees the sky): the true
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
