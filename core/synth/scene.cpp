// Synthetic scenes of known ice volume. Nothing public carries iced blades with measured volumes,
// so the chain is proven on renderings whose truth comes from the geometry itself.
//
// The camera is the ideal HBVCAM (calib::nominalCalibration): pinhole, 60 mm baseline, 80° HFOV,
// the object 0.85 m away and nearly fronto-parallel. A scene is rendered in stages, one file each:
//   look.cpp          the seed's light, textures and ice appearance
//   blade.cpp,        the objects as triangle meshes in their object frame (x, y in the object's
//   flat_objects.cpp  plane, h its height towards the camera), posed in the left camera frame
//   eye.cpp           each eye z-buffer rasterised (rasterizer.cpp) and shaded (shading.cpp) at
//                     supersampling² samples per pixel, box-filtered down; the truth maps;
//                     with refractive ice optics, what the eye sees under the ice (refraction.cpp);
//                     with gloss, the highlights each eye sees (highlight.cpp); with shadows,
//                     what the sun does not reach (shadow.cpp)
//   sensor.cpp        per frame: the capture's gain, Gaussian sensor noise, 8 bits and JPEG, like
//                     the camera's MJPEG stream
//   scene_files.cpp   the scene directory
// The geometry of each capture is rendered once, whatever the number of frames.
//
// The ice is a height field over the same triangulated planform as the clean surface, so its
// volume is exact for what is rendered: the sum over triangles of area × mean vertex thickness.
// The blade's ice amplitude is scaled so that this sum is the requested volume.
#include "core/synth/scene.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <optional>
#include <random>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "core/common/error.hpp"
#include "core/common/side_by_side.hpp"
#include "core/synth/blade.hpp"
#include "core/synth/eye.hpp"
#include "core/synth/flat_objects.hpp"
#include "core/synth/sensor.hpp"
#include "core/synth/shadow.hpp"

namespace icewatch::synth {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kPlateRoiInsetMm = 25.0;
// The blade lies flat side down on the table; the table sits a hair below so that the outline,
// where the blade's surface meets it, never depends on the z-buffer's rounding.
constexpr double kTableBelowBladeMm = 0.5;
// Clouds' contrast on the overcast's brightness (0.80-0.85): soft ones, about 12 grey levels.
constexpr double kCloudContrast = 0.05;

// The captures' geometry and what it says about the truth.
struct Geometry {
    std::vector<Mesh> before, after;
    std::vector<cv::Vec3d> outline;  // the object's outline in the before capture, camera frame
    double iceVolumeMm3 = 0.0;
    double maxIceThicknessMm = 0.0;
};

// The bead's front is ice standing on nothing: where the bead is absent (towards the root) there is
// no surface in front of the leading edge at all, not a sheet of zero thickness.
Mesh withoutBareTriangles(Mesh mesh) {
    const auto bare = [&mesh](int k) { return mesh.attributes[static_cast<std::size_t>(k)][kAttributeExtra] <= 0.0f; };
    std::erase_if(mesh.triangles, [&bare](const std::array<int, 3>& t) { return bare(t[0]) && bare(t[1]) && bare(t[2]); });
    return mesh;
}

// `look` lights the baseline, `afterLook` the current capture (the light may have turned between them).
Geometry bladeGeometry(const SceneSpec& spec, const Pose& before, const Pose& after, const Look& look,
                       const Look& afterLook) {
    GridSurface surface = bladeSurface(spec.ice, spec.seed);
    GridSurface front = beadFront(spec.ice, spec.seed);  // empty but for a bead (and icicles, below)
    if (front.nu > 0) {
        // A bead's cross-section grows with the square of its reach: the reach that carries the
        // requested volume over what the glaze under it holds, so that a bead stays as high as it
        // is wide and only a little ice makes a narrow one.
        const double beadMm3 = iceVolumeMm3(bladeSurface(IceKind::Bead, spec.seed)) + iceVolumeMm3(front);
        const double glazeMm3 = iceVolumeMm3(surface) + iceVolumeMm3(front) - beadMm3;
        const double overMm = kBeadReferenceMm * std::sqrt(std::max(0.05, spec.iceVolumeMm3 - glazeMm3) / beadMm3);
        surface = bladeSurface(spec.ice, spec.seed, overMm);
        front = beadFront(spec.ice, spec.seed, overMm);
    }
    if (spec.ice == IceKind::Ridges) {
        // Ridges keep their proportions too: their cross-section grows with the square of their size.
        const double sizeMm = kBeadReferenceMm * std::sqrt(spec.iceVolumeMm3 / iceVolumeMm3(surface));
        surface = bladeSurface(spec.ice, spec.seed, sizeMm);
    }
    if (spec.ice == IceKind::Icicles) {
        // Icicles keep their proportions: their volume grows with the cube of their size (the
        // runback band under them with its square, so the size is found twice).
        double sizeMm = kBeadReferenceMm;
        for (int pass = 0; pass < 2; ++pass) {
            front = icicleFront(spec.seed, sizeMm, spec.icicleLength);
            surface = bladeSurface(spec.ice, spec.seed, sizeMm);
            sizeMm *= std::cbrt(spec.iceVolumeMm3 / (iceVolumeMm3(surface) + iceVolumeMm3(front)));
        }
        front = icicleFront(spec.seed, sizeMm, spec.icicleLength);
        surface = bladeSurface(spec.ice, spec.seed, sizeMm);
    }
    double scale = spec.iceVolumeMm3 / (iceVolumeMm3(surface) + iceVolumeMm3(front));
    // A glaze wrapping the edges: their half-rounds are as wide as they are high, so they hold the
    // square of the scale, and the scale that carries the requested volume solves
    // scale·blade + scale²·edges = volume.
    const bool wrapsEdges = spec.iceOverEdges && spec.ice == IceKind::GlazeAll;
    if (wrapsEdges) {
        const double bladeMm3 = iceVolumeMm3(surface);
        const double edgesMm3 = iceVolumeMm3(glazeEdge(surface, true)) + iceVolumeMm3(glazeEdge(surface, false));
        scale = (std::sqrt(bladeMm3 * bladeMm3 + 4.0 * edgesMm3 * spec.iceVolumeMm3) - bladeMm3) / (2.0 * edgesMm3);
    }
    for (float& t : surface.ice) t = static_cast<float>(t * scale);
    for (float& t : front.ice) t = static_cast<float>(t * scale);
    std::vector<GridSurface> edges;
    if (wrapsEdges) edges = {glazeEdge(surface, true), glazeEdge(surface, false)};
    Geometry g;
    g.iceVolumeMm3 = iceVolumeMm3(surface) + iceVolumeMm3(front);
    for (const GridSurface& edge : edges) g.iceVolumeMm3 += iceVolumeMm3(edge);
    g.maxIceThicknessMm = *std::max_element(surface.ice.begin(), surface.ice.end());
    g.before.push_back(bladeMesh(surface, 0.0, before, look));
    g.after.push_back(bladeMesh(surface, 1.0, after, afterLook, kMaterialBlade, spec.optics));
    if (front.nu > 0) {
        g.after.push_back(withoutBareTriangles(bladeMesh(front, 1.0, after, afterLook, kMaterialBeadFront)));
    }
    for (const GridSurface& edge : edges) g.after.push_back(glazeEdgeMesh(edge, after, afterLook));
    g.outline = bladeOutline(surface, before, 10);
    if (spec.background == Background::Table) {
        g.before.push_back(tableMesh(-kTableBelowBladeMm - spec.tableGapMm, before, look));
        g.after.push_back(tableMesh(-kTableBelowBladeMm - spec.tableGapMm, after, afterLook));
    }
    return g;
}

Geometry blockGeometry(const SceneSpec& spec, const Pose& before, const Pose& after, const Look& look,
                       const Look& afterLook) {
    const double heightMm = spec.iceVolumeMm3 / (kBlockLengthMm * kBlockWidthMm);
    const bool onTable = spec.background == Background::Table;
    Geometry g;
    g.iceVolumeMm3 = heightMm * kBlockLengthMm * kBlockWidthMm;
    g.maxIceThicknessMm = heightMm;
    g.before = blockMeshes(0.0, onTable, before, look);
    g.after = blockMeshes(heightMm, onTable, after, afterLook);
    if (onTable) {
        g.before.push_back(tableMesh(-kPlateThicknessMm, before, look));
        g.after.push_back(tableMesh(-kPlateThicknessMm, after, afterLook));
    }
    const double hx = kPlateLengthMm / 2 - kPlateRoiInsetMm, hy = kPlateWidthMm / 2 - kPlateRoiInsetMm;
    for (const auto& corner : {cv::Vec2d(-hx, -hy), cv::Vec2d(hx, -hy), cv::Vec2d(hx, hy), cv::Vec2d(-hx, hy)}) {
        g.outline.push_back(before.toCamera(corner[0], corner[1], 0));
    }
    return g;
}

cv::Point2d projectLeft(const calib::StereoCalibration& c, const cv::Vec3d& p) {
    return {c.M1.at<double>(0, 0) * p[0] / p[2] + c.M1.at<double>(0, 2),
            c.M1.at<double>(1, 1) * p[1] / p[2] + c.M1.at<double>(1, 2)};
}

void checkSpec(const SceneSpec& spec) {
    if (spec.frameSize.width < 64 || spec.frameSize.height < 32 || spec.frameSize.width % 2 != 0) {
        throw InvalidInput("synthetic scene: frame size must be even in width and at least 64x32");
    }
    if (!(spec.iceVolumeMm3 >= 0) || spec.iceVolumeMm3 > 5e6) {
        throw InvalidInput("synthetic scene: ice volume must be between 0 and 5e6 mm3");
    }
    if (!(spec.blurPx >= 0 && spec.blurPx <= kMaxBlurPx)) {
        throw InvalidInput("synthetic scene: the lens's blur must be between 0 and 5 px");
    }
    if (spec.noiseSigma < 0 || spec.noiseSigma > 50) {
        throw InvalidInput("synthetic scene: noise sigma must be between 0 and 50 grey levels");
    }
    if (spec.jpegQuality < 1 || spec.jpegQuality > 100) {
        throw InvalidInput("synthetic scene: JPEG quality must be between 1 and 100");
    }
    if (spec.frames < 1 || spec.frames > kMaxFrames) {
        throw InvalidInput("synthetic scene: frames per capture must be between 1 and " + std::to_string(kMaxFrames));
    }
    if (spec.supersampling < 1 || spec.supersampling > 8) {
        throw InvalidInput("synthetic scene: supersampling must be between 1 and 8");
    }
    if (!(spec.lightChange >= kMinLightChange && spec.lightChange <= kMaxLightChange)) {
        throw InvalidInput("synthetic scene: light change must be between 0.2 and 3");
    }
    if (!(spec.sunAngleDeg >= 0 && spec.sunAngleDeg <= kMaxSunAngleDeg)) {
        throw InvalidInput("synthetic scene: the sun's angle from the view must be between 0 and 80 degrees");
    }
    if (!(spec.sunChange >= 0 && spec.sunChange <= kMaxSunChange)) {
        throw InvalidInput("synthetic scene: the sun's change must be between 0 and 3");
    }
    if (!(std::abs(spec.rollDeg) <= kMaxRollDeg)) {
        throw InvalidInput("synthetic scene: the object's roll must be between -180 and 180 degrees");
    }
    if (!(spec.distanceMm >= kMinDistanceMm && spec.distanceMm <= kMaxDistanceMm)) {
        throw InvalidInput("synthetic scene: the object's distance must be between 600 and 1500 mm");
    }
    if (!(spec.lightTurnDeg >= 0 && spec.lightTurnDeg <= kMaxLightTurnDeg)) {
        throw InvalidInput("synthetic scene: the light's turn must be between 0 and 60 degrees");
    }
    if (!(spec.cloudDrift >= 0 && spec.cloudDrift <= kMaxCloudDrift)) {
        throw InvalidInput("synthetic scene: the clouds' drift must be between 0 and 0.5 of the image");
    }
    if (!(std::abs(spec.tiltDeg) <= kMaxTiltDeg && std::abs(spec.swingDeg) <= kMaxTiltDeg)) {
        throw InvalidInput("synthetic scene: the object's tilt and swing must be between -45 and 45 degrees");
    }
    if (!(spec.gloss >= 0 && spec.gloss <= kMaxGloss)) {
        throw InvalidInput("synthetic scene: the gloss must be between 0 and 1");
    }
    // 0 keeps the seed's look; anything else must lie in the override's range.
    auto overrideIn = [](double value, double lo, double hi) { return value == 0.0 || (value >= lo && value <= hi); };
    if (!overrideIn(spec.textureContrast, kMinTextureContrast, kMaxTextureContrast)) {
        throw InvalidInput("synthetic scene: the texture's contrast must be between 0.005 and 0.3 (0: the seed's)");
    }
    if (!overrideIn(spec.textureFeatureMm, kMinTextureFeatureMm, kMaxTextureFeatureMm)) {
        throw InvalidInput("synthetic scene: the texture's feature size must be between 0.5 and 50 mm (0: the seed's)");
    }
    if (!overrideIn(spec.iceWhiteness, kMinIceWhiteness, kMaxIceWhiteness)) {
        throw InvalidInput("synthetic scene: the ice's whiteness must be between 0.4 and 1 (0: the seed's)");
    }
    if (!(spec.tableGapMm >= 0 && spec.tableGapMm <= kMaxTableGapMm)) {
        throw InvalidInput("synthetic scene: the table's gap must be between 0 and 100 mm");
    }
    if (spec.tableGapMm > 0 && (spec.kind != SceneKind::Blade || spec.background != Background::Table)) {
        throw InvalidInput("synthetic scene: the table's gap is a blade's on a table (a block sits on its plate)");
    }
    if (spec.iceOverEdges && (spec.kind != SceneKind::Blade || spec.ice != IceKind::GlazeAll)) {
        throw InvalidInput("synthetic scene: ice over the edges is a glaze-all blade's (the other kinds end where they end)");
    }
    if (!(spec.icicleLength >= kMinIcicleLength && spec.icicleLength <= kMaxIcicleLength)) {
        throw InvalidInput("synthetic scene: the icicles' length scale must be between 0.1 and 2");
    }
    if (spec.icicleLength != 1.0 && (spec.kind != SceneKind::Blade || spec.ice != IceKind::Icicles)) {
        throw InvalidInput("synthetic scene: the icicles' length is an icicled blade's (--ice icicles)");
    }
    if (spec.kind == SceneKind::Block && spec.ice != IceKind::LeadingEdge) {
        throw InvalidInput("synthetic scene: the ice kind is the blade's; a block scene's ice is the block");
    }
    // The block's plate and ice have looks of their own, and its ice is opaque: the blade's look
    // and optics would be accepted and silently change nothing.
    if (spec.kind == SceneKind::Block && (spec.textureContrast != 0.0 || spec.textureFeatureMm != 0.0 ||
                                          spec.iceWhiteness != 0.0 || spec.optics != IceOptics::Painted)) {
        throw InvalidInput("synthetic scene: the texture's contrast and feature size, the ice's whiteness and "
                           "its optics are the blade's; a block scene's plate and ice have their own");
    }
    if (spec.kind == SceneKind::Block && spec.iceVolumeMm3 / (kBlockLengthMm * kBlockWidthMm) > 200.0) {
        throw InvalidInput("synthetic scene: a block of this volume would be taller than 200 mm");
    }
}

template <typename Enum, std::size_t N>
Enum parseName(std::string_view what, std::string_view name, const std::pair<Enum, const char*> (&names)[N]) {
    std::string known;
    for (const auto& [value, text] : names) {
        if (name == text) return value;
        known += (known.empty() ? "" : ", ") + std::string(text);
    }
    throw InvalidInput("unknown " + std::string(what) + " \"" + std::string(name) + "\" (" + known + ")");
}

template <typename Enum, std::size_t N>
std::string nameOf(Enum value, const std::pair<Enum, const char*> (&names)[N]) {
    for (const auto& [v, text] : names) {
        if (v == value) return text;
    }
    return "?";
}

constexpr std::pair<SceneKind, const char*> kSceneNames[] = {{SceneKind::Blade, "blade"}, {SceneKind::Block, "block"}};
constexpr std::pair<IceKind, const char*> kIceNames[] = {
    {IceKind::LeadingEdge, "leading-edge"}, {IceKind::GlazeAll, "glaze-all"}, {IceKind::Patches, "patches"},
    {IceKind::Bead, "bead"}, {IceKind::BeadGlaze, "bead-glaze"}, {IceKind::Ridges, "ridges"},
    {IceKind::Shed, "shed"}, {IceKind::Icicles, "icicles"}};
constexpr std::pair<MotionKind, const char*> kMotionNames[] = {{MotionKind::None, "none"}, {MotionKind::Small, "small"},
                                                              {MotionKind::Large, "large"}};
constexpr std::pair<Background, const char*> kBackgroundNames[] = {{Background::Sky, "sky"},
                                                                   {Background::Table, "table"}};
constexpr std::pair<IceOptics, const char*> kOpticsNames[] = {{IceOptics::Painted, "painted"},
                                                              {IceOptics::Refractive, "refractive"}};
constexpr std::pair<ToneCurve, const char*> kToneCurveNames[] = {
    {ToneCurve::Linear, "linear"}, {ToneCurve::Gamma, "gamma"}, {ToneCurve::Filmic, "filmic"}};

}  // namespace

SceneKind parseSceneKind(std::string_view name) { return parseName("scene", name, kSceneNames); }
IceKind parseIceKind(std::string_view name) { return parseName("ice kind", name, kIceNames); }
MotionKind parseMotionKind(std::string_view name) { return parseName("motion", name, kMotionNames); }
Background parseBackground(std::string_view name) { return parseName("background", name, kBackgroundNames); }
IceOptics parseIceOptics(std::string_view name) { return parseName("ice optics", name, kOpticsNames); }
ToneCurve parseToneCurve(std::string_view name) { return parseName("tone curve", name, kToneCurveNames); }
std::string sceneKindName(SceneKind kind) { return nameOf(kind, kSceneNames); }
std::string iceKindName(IceKind kind) { return nameOf(kind, kIceNames); }
std::string motionKindName(MotionKind kind) { return nameOf(kind, kMotionNames); }
std::string backgroundName(Background background) { return nameOf(background, kBackgroundNames); }
std::string iceOpticsName(IceOptics optics) { return nameOf(optics, kOpticsNames); }
std::string toneCurveName(ToneCurve curve) { return nameOf(curve, kToneCurveNames); }

SyntheticScene renderScene(const SceneSpec& spec) {
    checkSpec(spec);
    std::mt19937 random(spec.seed);
    auto uniform = [&random](double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(random); };

    SyntheticScene scene;
    const cv::Size eye{spec.frameSize.width / 2, spec.frameSize.height};
    scene.calibration = calib::nominalCalibration(eye, spec.horizontalFovDeg, spec.baselineMm);
    // The block is the seed paper's lab rig under fixed lamps; the blade is outdoors, lit as the
    // day and the weather have it.
    scene.look = drawLook(spec.seed, spec.kind == SceneKind::Block);
    scene.look.gloss = spec.gloss;
    if (spec.textureContrast > 0) scene.look.compositeContrast = spec.textureContrast;
    if (spec.textureFeatureMm > 0) scene.look.compositeFeatureMm = spec.textureFeatureMm;
    if (spec.iceWhiteness > 0) scene.look.iceWhiteness = spec.iceWhiteness;
    if (spec.sunAngleDeg > 0) {
        const cv::Vec3d& l = scene.look.towardsLight;
        const double azimuth = std::atan2(l[1], l[0]), angle = spec.sunAngleDeg * kPi / 180.0;
        scene.look.towardsLight = {std::sin(angle) * std::cos(azimuth), std::sin(angle) * std::sin(azimuth),
                                   -std::cos(angle)};
    }

    // Nearly fronto-parallel, tilted by a few degrees so the surface spans a range of disparities.
    const bool blade = spec.kind == SceneKind::Blade;
    // The roll turns the object in the image (a blade parked at another angle), about the view axis;
    // the tilt and the swing turn it out of the view (a blade on a table seen from above at an angle).
    const Pose before{rotationFromDegrees({spec.tiltDeg, 0, 0}) * rotationFromDegrees({0, spec.swingDeg, 0}) *
                          rotationFromDegrees({0, 0, spec.rollDeg}) *
                          rotationFromDegrees({uniform(-3, 3), uniform(2, 5), uniform(-2, 2)}),
                      {uniform(-10, 10), uniform(-10, 10), spec.distanceMm}};
    // The motion is drawn either way, so that a seed's pose, look and noise do not depend on it.
    const double scale = spec.motion == MotionKind::Large ? 5.0 : 1.0;
    const double maxShiftMm = (blade ? 3.0 : 1.0) * scale, maxTurnDeg = (blade ? 0.3 : 0.1) * scale;
    scene.motion.rotationDeg = {uniform(-maxTurnDeg, maxTurnDeg), uniform(-maxTurnDeg, maxTurnDeg),
                                uniform(-maxTurnDeg, maxTurnDeg)};
    scene.motion.translationMm = {uniform(-maxShiftMm, maxShiftMm), uniform(-maxShiftMm, maxShiftMm),
                                  uniform(-maxShiftMm, maxShiftMm)};
    if (spec.motion == MotionKind::None) scene.motion = {};
    scene.motion.pivotMm = before.translation;
    const Pose after{rotationFromDegrees(scene.motion.rotationDeg) * before.rotation,
                     before.translation + scene.motion.translationMm};

    // The sun moved between the captures, across the sky and in height: its direction turned about
    // an axis in the image plane halfway between the horizontal and the vertical, so the shading of
    // a curved surface changes unevenly (a leading edge facing up otherwise than a flat middle).
    Look afterLook = scene.look;
    const double turn = spec.lightTurnDeg / std::sqrt(2.0);
    afterLook.towardsLight = rotationFromDegrees({turn, turn, 0}) * scene.look.towardsLight;
    // The sun's light, and what wet ice mirrors of it, change; the sky's light does not.
    afterLook.diffuse = scene.look.diffuse * spec.sunChange;
    afterLook.gloss = scene.look.gloss * spec.sunChange;
    const Geometry geometry = blade ? bladeGeometry(spec, before, after, scene.look, afterLook)
                                    : blockGeometry(spec, before, after, scene.look, afterLook);
    scene.iceVolumeMm3 = geometry.iceVolumeMm3;
    scene.maxIceThicknessMm = geometry.maxIceThicknessMm;
    for (const cv::Vec3d& p : geometry.outline) scene.roi.push_back(projectLeft(scene.calibration, p));
    const cv::Rect eyeRect{8, 8, eye.width - 16, eye.height - 16};
    for (const cv::Point2d& p : scene.roi) {
        if (!eyeRect.contains(cv::Point(cvRound(p.x), cvRound(p.y)))) {
            throw InvalidInput("synthetic scene: the object does not fit in the left eye at this roll and distance");
        }
    }

    const double clouds = spec.cloudDrift > 0 ? kCloudContrast : 0.0;
    // Each capture's shadows fall from its own light; the table lies under everything and hides
    // the light from nothing.
    auto shadowsOf = [&spec](const std::vector<Mesh>& meshes, const Look& lit) -> std::optional<ShadowMap> {
        if (!spec.shadows) return std::nullopt;
        std::vector<Mesh> casters;
        std::copy_if(meshes.begin(), meshes.end(), std::back_inserter(casters),
                     [](const Mesh& m) { return m.material != kMaterialTable; });
        return ShadowMap(casters, lit.towardsLight);
    };
    const std::optional<ShadowMap> beforeShadows = shadowsOf(geometry.before, scene.look);
    const std::optional<ShadowMap> afterShadows = shadowsOf(geometry.after, afterLook);
    const Shading beforeShading{scene.look, spec.ice, spec.seed, clouds, 0.0,
                                beforeShadows ? &*beforeShadows : nullptr, spec.background};
    const Shading afterShading{afterLook, spec.ice, spec.seed, clouds, spec.cloudDrift,
                               afterShadows ? &*afterShadows : nullptr, spec.background};
    EyeTruth beforeTruth, afterTruth;
    auto light = [&](const std::vector<Mesh>& meshes, const Shading& shading, EyeTruth& truth) {
        const double b = spec.baselineMm;
        const cv::Mat left = renderEye(meshes, shading, scene.calibration, 0.0, spec.supersampling, b, &truth);
        const cv::Mat right = renderEye(meshes, shading, scene.calibration, b, spec.supersampling);
        return joinSideBySide(left, right);
    };
    auto noiseSeeds = [&] {
        std::vector<std::uint32_t> seeds(static_cast<std::size_t>(spec.frames));
        // The noise draw mixes into every frame's seed (Knuth's multiplicative hash spreads small
        // numbers over all the bits); 0 keeps the seed's own draw.
        for (auto& s : seeds) s = static_cast<std::uint32_t>(random()) ^ (spec.noiseDraw * 2654435761u);
        return seeds;
    };
    const Tone tone = spec.toneCurve == ToneCurve::Filmic  ? Tone::Filmic
                      : spec.toneCurve == ToneCurve::Gamma ? Tone::Gamma
                                                           : Tone::Linear;
    scene.beforeJpeg = exposeFrames(light(geometry.before, beforeShading, beforeTruth),
                                    {1.0, spec.noiseSigma, spec.jpegQuality, spec.blurPx, tone}, noiseSeeds());
    scene.afterJpeg = exposeFrames(light(geometry.after, afterShading, afterTruth),
                                   {spec.lightChange, spec.noiseSigma, spec.jpegQuality, spec.blurPx, tone},
                                   noiseSeeds());
    scene.before = cv::imdecode(scene.beforeJpeg.front(), cv::IMREAD_COLOR);
    scene.after = cv::imdecode(scene.afterJpeg.front(), cv::IMREAD_COLOR);
    scene.beforeDisparity = beforeTruth.disparity;
    scene.afterDisparity = afterTruth.disparity;
    scene.afterIceMm = afterTruth.iceMm;
    return scene;
}

}  // namespace icewatch::synth
