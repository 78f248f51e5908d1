// icewatch floor: how well a rendered scene's images can fix the ice volume at all. With the true
// disparities of both captures (icewatch synth --truth-maps), the noise floor of the mean disparity
// is measured in each capture (core/synth/disparity_floor.hpp) and carried to the volume: a shift δ
// of the disparities of a set of pixels moves the volume by δ·Σ Z⁴/(f³·B) over them.
//   floor: over the pixels that truly carry ice, in both captures. An oracle that knew where the
//     ice is and registered the two captures perfectly would still be this far off (1 σ): no
//     matcher, registration or integration can do better on these images.
//   whole object: over every pixel of the object, as integrating the thickness over the whole
//     outline does when nothing (a registration on the unchanged surface) removes the noise the
//     two captures have in common there.
#include <cmath>
#include <fstream>
#include <iostream>

#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "core/common/error.hpp"
#include "core/common/side_by_side.hpp"
#include "core/stereo/disparity_io.hpp"
#include "core/synth/disparity_floor.hpp"
#include "core/volume/scene_files.hpp"
#include "tools/icewatch/command.hpp"
#include "tools/icewatch/scene_recordings.hpp"

namespace icewatch::cli {

namespace {

// The truth maps are in the left eye's own pixels, which are the rectified ones only when the
// calibration has no distortion and no rectifying turn (as every rendered scene's has).
void requireIdealCalibration(const calib::StereoCalibration& c, const std::filesystem::path& file) {
    const bool ideal = cv::norm(c.D1) == 0 && cv::norm(c.R1, cv::Mat::eye(3, 3, CV_64F)) < 1e-9 &&
                       cv::norm(c.P1(cv::Rect(0, 0, 3, 3)), c.M1) < 1e-6;
    if (!ideal) {
        throw Error(kExitDataErr, file.string() +
                                      ": the truth maps line up with the rectified left eye only for an undistorted, "
                                      "unrotated calibration (a rendered scene's)");
    }
}

cv::Mat readTruthMap(const std::filesystem::path& path, cv::Size eye) {
    if (!std::filesystem::exists(path)) {
        throw Error(kExitNoInput, path.string() + ": missing (render the scene with icewatch synth --truth-maps)");
    }
    cv::Mat map = stereo::readPfm(path);
    if (map.size() != eye) {
        throw Error(kExitDataErr, path.string() + ": " + std::to_string(map.cols) + "x" + std::to_string(map.rows) +
                                      ", not the eye size " + std::to_string(eye.width) + "x" +
                                      std::to_string(eye.height));
    }
    return map;
}

// mm³ of volume per pixel of disparity shifted over the selected pixels: Σ (Z²/(f·B))·(Z/f)².
double volumePerPixelOfDisparity(const cv::Mat& disparity, const cv::Mat& select, double focalPx, double baselineMm,
                                 int& pixels) {
    double sum = 0;
    pixels = 0;
    for (int y = 0; y < disparity.rows; ++y)
        for (int x = 0; x < disparity.cols; ++x) {
            const float d = disparity.at<float>(y, x);
            if (d <= 0 || (!select.empty() && !select.at<std::uint8_t>(y, x))) continue;
            const double z = focalPx * baselineMm / d;
            sum += (z * z / (focalPx * baselineMm)) * (z / focalPx) * (z / focalPx);
            ++pixels;
        }
    return sum;
}

nlohmann::json floorJson(const synth::DisparityFloor& f) {
    return {{"boxes", f.boxes},
            {"box_sigma_px", f.boxSigmaPx},
            {"box_mean_px", f.boxMeanPx},
            {"object_pixels", f.objectPixels},
            {"residual_sigma_grey", f.residualSigma},
            {"mean_gradient_sq", f.meanGradientSq}};
}

}  // namespace

void addFloorCommand(CLI::App& app, const GlobalOptions& /*global*/, RunFunction& run) {
    CLI::App* cmd = app.add_subcommand(
        "floor", "the ice volume's noise floor on a rendered scene's images (needs icewatch synth --truth-maps)");
    struct Options {
        std::string scene;
        int boxPx = 31;
        double iceThresholdMm = 0.05;
        bool json = false;
    };
    auto o = std::make_shared<Options>();
    cmd->add_option("--scene", o->scene, "scene directory written by icewatch synth --truth-maps")->required();
    cmd->add_option("--box", o->boxPx, "box side, px, over which one shift is estimated")->check(CLI::Range(5, 255));
    cmd->add_option("--ice-threshold-mm", o->iceThresholdMm, "true ice thicker than this counts as iced");
    cmd->add_flag("--json", o->json, "print the result as one JSON object");
    cmd->callback([&run, o] {
        run = [o] {
            const std::filesystem::path dir = o->scene;
            const volume::SceneFiles scene = volume::loadSceneDirectory(dir, readCaptureRecording);
            if (!scene.unusable.empty()) throw Error(kExitDataErr, scene.unusable);
            requireIdealCalibration(scene.calibration, dir / "calibration.yaml");
            const cv::Size eye = scene.calibration.imageSize;
            const cv::Mat truthBefore = readTruthMap(dir / "truth_disparity_before.pfm", eye);
            const cv::Mat truthAfter = readTruthMap(dir / "truth_disparity_after.pfm", eye);
            const cv::Mat iceMm = readTruthMap(dir / "truth_ice_mm.pfm", eye);
            double truthVolume = 0;
            {
                if (!std::filesystem::exists(dir / "truth.json")) {
                    throw Error(kExitNoInput, (dir / "truth.json").string() + ": missing");
                }
                std::ifstream in(dir / "truth.json");
                const auto truth = nlohmann::json::parse(in, nullptr, false);
                if (truth.is_discarded() || !truth.contains("ice_volume_mm3") || !truth["ice_volume_mm3"].is_number()) {
                    throw Error(kExitDataErr, (dir / "truth.json").string() + ": no number ice_volume_mm3");
                }
                truthVolume = truth["ice_volume_mm3"].get<double>();
            }

            // The captures as the chain measures them: averaged in floating point (as they were read).
            const StereoPair before = splitSideBySide(scene.before.frame);
            const StereoPair after = splitSideBySide(scene.after.frame);
            const synth::DisparityFloor fb = synth::measureDisparityFloor(before.left, before.right, truthBefore, o->boxPx);
            const synth::DisparityFloor fa = synth::measureDisparityFloor(after.left, after.right, truthAfter, o->boxPx);
            if (fb.boxes < 2 || fa.boxes < 2) {
                throw Error(kExitDataErr, dir.string() + ": the object holds fewer than two whole " +
                                              std::to_string(o->boxPx) + " px boxes; try a smaller --box");
            }
            const double f = scene.calibration.P1.at<double>(0, 0), b = scene.calibration.baselineMm();
            // Whole object: each capture's mean-disparity noise over all of its pixels.
            int nb = 0, na = 0;
            const double wb = volumePerPixelOfDisparity(truthBefore, {}, f, b, nb);
            const double wa = volumePerPixelOfDisparity(truthAfter, {}, f, b, na);
            const double wholeMm3 = std::hypot(wb * fb.meanSigmaPx(nb), wa * fa.meanSigmaPx(na));
            // The floor: an oracle integrating only where the ice truly is (the same pixels in both).
            const cv::Mat iced = iceMm > o->iceThresholdMm;
            int ni = 0;
            const double wi = volumePerPixelOfDisparity(truthAfter, iced, f, b, ni);
            const double icedMm3 = std::hypot(wi * fb.meanSigmaPx(ni), wi * fa.meanSigmaPx(ni));
            const auto percent = [&](double v) { return truthVolume > 0 ? 100.0 * v / truthVolume : 0.0; };
            const nlohmann::json out{{"box_px", o->boxPx},
                                     {"before", floorJson(fb)},
                                     {"after", floorJson(fa)},
                                     {"truth_volume_mm3", truthVolume},
                                     {"object_pixels", na},
                                     {"iced_pixels", ni},
                                     {"floor_mm3", icedMm3},
                                     {"floor_percent", percent(icedMm3)},
                                     {"whole_object_mm3", wholeMm3},
                                     {"whole_object_percent", percent(wholeMm3)}};
            if (o->json) {
                std::cout << out.dump() << "\n";
            } else {
                std::cout << "disparity floor per " << o->boxPx << " px box: " << fb.boxSigmaPx << " / " << fa.boxSigmaPx
                          << " px (before / after); volume floor (1 sigma, over the iced pixels) " << icedMm3
                          << " mm3 = " << percent(icedMm3) << " %; over the whole object " << wholeMm3 << " mm3 = "
                          << percent(wholeMm3) << " %\n";
            }
            return 0;
        };
    });
}

}  // namespace icewatch::cli
