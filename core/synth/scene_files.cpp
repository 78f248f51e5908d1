// The scene directory: what icewatch volume, icewatch floor and the benchmark read, and the truth
// they are measured against, with every option the scene was rendered with.
#include <fstream>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "core/common/error.hpp"
#include "core/stereo/disparity_io.hpp"
#include "core/synth/scene.hpp"

namespace icewatch::synth {

namespace {

void writeImage(const std::filesystem::path& path, const cv::Mat& image) {
    bool written = false;
    try {
        written = cv::imwrite(path.string(), image);
    } catch (const cv::Exception&) {
        written = false;
    }
    if (!written) {
        throw Error(kExitCantCreate, path.string() + ": cannot write the image");
    }
}

void writeJson(const std::filesystem::path& path, const nlohmann::json& json) {
    std::ofstream out(path);
    out << json.dump(2) << "\n";
    if (!out) {
        throw Error(kExitCantCreate, path.string() + ": cannot write");
    }
}

nlohmann::json vec3(const cv::Vec3d& v) { return {v[0], v[1], v[2]}; }

nlohmann::json truthJson(const SyntheticScene& scene, const SceneSpec& spec) {
    const Look& look = scene.look;
    return {{"scene", sceneKindName(spec.kind)},
            {"ice_volume_mm3", scene.iceVolumeMm3},
            {"max_ice_thickness_mm", scene.maxIceThicknessMm},
            {"seed", spec.seed},
            {"mode", std::to_string(spec.frameSize.width) + "x" + std::to_string(spec.frameSize.height)},
            {"noise_sigma", spec.noiseSigma},
            {"noise_draw", spec.noiseDraw},
            {"jpeg_quality", spec.jpegQuality},
            {"blur_px", spec.blurPx},
            {"tone_curve", toneCurveName(spec.toneCurve)},
            {"frames", spec.frames},
            {"supersampling", spec.supersampling},
            {"ice", spec.kind == SceneKind::Blade ? iceKindName(spec.ice) : "block"},
            {"motion", motionKindName(spec.motion)},
            {"background", backgroundName(spec.background)},
            {"ice_optics", iceOpticsName(spec.optics)},
            {"light_change", spec.lightChange},
            {"light_turn_deg", spec.lightTurnDeg},
            {"sun_change", spec.sunChange},
            {"sun_angle_deg", spec.sunAngleDeg},
            {"distance_mm", spec.distanceMm},
            {"roll_deg", spec.rollDeg},
            {"tilt_deg", spec.tiltDeg},
            {"swing_deg", spec.swingDeg},
            {"cloud_drift", spec.cloudDrift},
            {"shadows", spec.shadows},
            {"table_gap_mm", spec.tableGapMm},
            {"ice_over_edges", spec.iceOverEdges},
            {"icicle_length", spec.icicleLength},
            {"motion_rotation_deg", vec3(scene.motion.rotationDeg)},
            {"motion_translation_mm", vec3(scene.motion.translationMm)},
            {"motion_pivot_mm", vec3(scene.motion.pivotMm)},
            {"look",
             {{"towards_light", vec3(look.towardsLight)},
              {"ambient", look.ambient},
              {"composite_albedo", look.compositeAlbedo},
              {"composite_contrast", look.compositeContrast},
              {"composite_feature_mm", look.compositeFeatureMm},
              {"ice_whiteness", look.iceWhiteness},
              {"ice_translucency_mm", look.iceTranslucencyMm},
              {"glaze_keeps_texture", look.glazeKeepsTexture},
              {"gloss", look.gloss},
              {"table_grain_deg", look.tableGrainDeg}}}};
}

}  // namespace

void writeScene(const SyntheticScene& scene, const SceneSpec& spec, const std::filesystem::path& dir, bool truthMaps) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) {
        throw Error(kExitCantCreate, dir.string() + ": cannot create the scene directory (" + ec.message() + ")");
    }
    calib::saveCalibration(dir / "calibration.yaml", scene.calibration);
    if (scene.beforeJpeg.size() <= 1 && scene.afterJpeg.size() <= 1) {
        writeImage(dir / "before.png", scene.before);
        writeImage(dir / "after.png", scene.after);
    }
    if (truthMaps) {
        stereo::writePfm(dir / "truth_disparity_before.pfm", scene.beforeDisparity);
        stereo::writePfm(dir / "truth_disparity_after.pfm", scene.afterDisparity);
        stereo::writePfm(dir / "truth_ice_mm.pfm", scene.afterIceMm);
    }
    nlohmann::json polygon = nlohmann::json::array();
    for (const auto& p : scene.roi) polygon.push_back({p.x, p.y});
    writeJson(dir / "roi.json", {{"eye", "left"}, {"polygon", polygon}});
    writeJson(dir / "truth.json", truthJson(scene, spec));
}

}  // namespace icewatch::synth
