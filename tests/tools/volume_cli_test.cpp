// icewatch synth and icewatch volume as a supervisor runs them: exit statuses and messages.
#include <filesystem>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "core/common/exit_codes.hpp"
#include "core/stereo/disparity_io.hpp"
#include "tests/support/run_program.hpp"
#include "tests/support/test_paths.hpp"

namespace icewatch {
namespace {

std::string icewatchBin() { return (test::binDir() / "icewatch").string(); }

// icewatch synth with these scene arguments, written into dir.
test::ProgramResult synth(const std::filesystem::path& dir, std::vector<std::string> arguments) {
    arguments.insert(arguments.begin(), {icewatchBin(), "synth"});
    arguments.insert(arguments.end(), {"--out", dir.string()});
    return test::runProgram(arguments);
}

std::filesystem::path smallScene(const std::filesystem::path& base = test::freshTempDir(), bool truthMaps = false) {
    const auto dir = base / "scene";
    std::vector<std::string> arguments{"--scene", "block", "--ice-volume-mm3", "417391", "--mode", "640x240",
                                       "--supersampling", "1"};
    if (truthMaps) arguments.push_back("--truth-maps");
    const auto r = synth(dir, arguments);
    EXPECT_EQ(r.status, 0) << r.err;
    return dir;
}

test::ProgramResult runVolume(const std::filesystem::path& dir) {
    return test::runProgram({icewatchBin(), "volume", "--scene", dir.string(), "--stereo-method", "sgbm", "--json"});
}

TEST(VolumeCli, SynthWritesACompleteSceneDirectory) {
    const auto dir = smallScene();
    for (const char* name : {"calibration.yaml", "before.png", "after.png", "roi.json", "truth.json"}) {
        EXPECT_TRUE(std::filesystem::exists(dir / name)) << name;
    }
    std::ifstream truth(dir / "truth.json");
    EXPECT_DOUBLE_EQ(nlohmann::json::parse(truth)["ice_volume_mm3"].get<double>(), 417391.0);
}

TEST(VolumeCli, JsonSaysWhereTheCurrentCaptureWasMatchedAndThePeakMemory) {
    const auto dir = smallScene();
    const auto r = test::runProgram({icewatchBin(), "volume", "--scene", dir.string(), "--stereo-method", "sgbm",
                                     "--json", "--compare-full-frame", "--compare-slanted"});
    ASSERT_TRUE(r.status == 0 || r.status == 1) << r.err;  // ok or refused: both print the document
    const auto out = nlohmann::json::parse(r.out);
    const auto& m = out.at("matched_region");
    EXPECT_FALSE(m.at("full_frame").get<bool>()) << "the scene has roi.json: the current capture is matched around it";
    EXPECT_GT(m.at("box").at("width").get<int>(), 0);
    EXPECT_LE(m.at("box").at("width").get<int>(), 320);
    EXPECT_LT(m.at("min_disparity").get<int>(), m.at("max_disparity").get<int>());
    EXPECT_GT(out.at("peak_rss_mb").get<double>(), 1.0);
    const auto& full = out.at("full_frame");
    EXPECT_GT(full.at("capture_ms").get<double>(), 0.0);
    EXPECT_GT(full.at("speedup").get<double>(), 0.0);
    // The slanted windows as they were, beside them as they are: both ran, and measured alike.
    const auto& slanted = out.at("slanted_before");
    EXPECT_GT(slanted.at("slanted_ms").get<double>(), 0.0);
    EXPECT_GT(slanted.at("slanted_now_ms").get<double>(), 0.0);
    EXPECT_EQ(slanted.at("status"), out.at("status"));
    if (out.at("status") == "ok") {
        EXPECT_NEAR(slanted.at("volume_mm3").get<double>(), out.at("volume_mm3").get<double>(),
                    0.5 * out.at("uncertainty_mm3").get<double>());
    }
}

// The registered motion is printed in the form of a rendered scene's truth (a rotation vector and
// a translation), current -> baseline: applied to where the object's origin went, it gives back
// where the origin was, and its rotation undoes the rendered one.
TEST(VolumeCli, JsonGivesTheRegisteredMotionAgainstWhichTheTruthCanBeChecked) {
    const auto dir = smallScene();
    const auto r = runVolume(dir);
    ASSERT_EQ(r.status, 0) << r.err << r.out;
    const auto out = nlohmann::json::parse(r.out);
    std::ifstream truthFile(dir / "truth.json");
    const auto truth = nlohmann::json::parse(truthFile);
    auto vec = [](const nlohmann::json& a) { return cv::Vec3d(a.at(0), a.at(1), a.at(2)); };
    const cv::Vec3d pivot = vec(truth.at("motion_pivot_mm")), moved = vec(truth.at("motion_translation_mm"));
    const cv::Vec3d turned = vec(truth.at("motion_rotation_deg"));
    ASSERT_GT(cv::norm(moved), 0.1) << "the scene's object moved";
    const auto& motion = out.at("registration_motion");
    cv::Matx33d rotation;
    cv::Rodrigues(vec(motion.at("rotation_vector_deg")) * (CV_PI / 180.0), rotation);
    const cv::Vec3d back = rotation * (pivot + moved) + vec(motion.at("translation_mm"));
    // A small single-frame block: the registration is good to a few tenths of a millimetre
    // against a shift of about a millimetre, and to about 0.05° against a turn of about as much
    // (too small to tell its direction here; degrees, not radians).
    EXPECT_LT(cv::norm(back - pivot), 0.4 * cv::norm(moved)) << back << " against " << pivot;
    EXPECT_LT(cv::norm(vec(motion.at("rotation_vector_deg")) + turned), 0.1) << "degrees";
}

TEST(VolumeCli, MissingFileIsNamed) {
    const auto dir = smallScene();
    std::filesystem::remove(dir / "after.png");
    const auto r = runVolume(dir);
    EXPECT_EQ(r.status, kExitNoInput);
    EXPECT_NE(r.err.find("after.png"), std::string::npos) << r.err;
}

TEST(VolumeCli, FrameOfWrongSizeIsNamed) {
    const auto dir = smallScene();
    cv::imwrite((dir / "before.png").string(), cv::Mat(100, 200, CV_8UC3, cv::Scalar::all(90)));
    const auto r = runVolume(dir);
    EXPECT_EQ(r.status, kExitDataErr);
    EXPECT_NE(r.err.find("before.png"), std::string::npos) << r.err;
}

// A recording the camera could not see well in (the sun in the lens: no frame passes its health
// check) is a measurement refused with the frames' reasons, not malformed input.
TEST(VolumeCli, ACaptureWithoutUsableFramesIsRefusedWithTheReason) {
    const auto dir = test::freshTempDir() / "glare";
    const auto rendered = synth(dir, {"--scene", "block", "--ice-volume-mm3", "1000", "--mode", "640x240",
                                      "--supersampling", "1", "--frames", "2", "--light-change", "3"});
    ASSERT_EQ(rendered.status, 0) << rendered.err;
    const auto r = runVolume(dir);
    EXPECT_EQ(r.status, kExitFailure) << r.err;
    const auto out = nlohmann::json::parse(r.out);
    EXPECT_EQ(out.at("status"), "refused");
    const std::string reason = out.at("reason");
    EXPECT_NE(reason.find("after: capture: 0 usable frames of 2"), std::string::npos) << reason;
    EXPECT_NE(reason.find("000001.jpg: left eye: 100.0 % of pixels saturated"), std::string::npos) << reason;
    EXPECT_EQ(out.at("current_capture").at("frames_dropped").size(), 2u);
    EXPECT_EQ(out.at("baseline_capture").at("frames_used"), 2);
}

// Brighter light that clips the sky behind the object but not the object: the frames are not
// washed out, and whether the object can be measured is the region's gate to say. Refusing the
// frames for their clipped share refused blocks and blades that measured inside their uncertainty.
TEST(VolumeCli, ASkyClippedBehindTheObjectDoesNotDropTheFrames) {
    const auto dir = test::freshTempDir() / "bright";
    const auto rendered = synth(dir, {"--scene", "block", "--ice-volume-mm3", "417391", "--mode", "640x240",
                                      "--supersampling", "1", "--frames", "2", "--light-change", "1.2"});
    ASSERT_EQ(rendered.status, 0) << rendered.err;
    const cv::Mat frame = cv::imread((dir / "after" / "000001.jpg").string(), cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(frame.empty());
    const cv::Mat leftEye = frame.colRange(0, frame.cols / 2);
    const double clipped = 100.0 * cv::countNonZero(leftEye >= 250) / static_cast<double>(leftEye.total());
    ASSERT_GT(clipped, 20.0) << "the scene must clip more than the frame check once allowed";

    const auto r = runVolume(dir);
    ASSERT_EQ(r.status, 0) << r.out << r.err;
    const auto out = nlohmann::json::parse(r.out);
    EXPECT_EQ(out.at("current_capture").at("frames_used"), 2);
    EXPECT_TRUE(out.at("current_capture").at("frames_dropped").empty());
    const double error = std::abs(out.at("volume_mm3").get<double>() - 417391.0);
    EXPECT_LT(error, out.at("uncertainty_mm3").get<double>());
}

TEST(VolumeCli, CalibrationOfAnotherModeIsRefused) {
    const auto base = test::freshTempDir();
    const auto dir = smallScene(base);
    const auto other = base / "other";
    ASSERT_EQ(synth(other, {"--scene", "block", "--ice-volume-mm3", "1000", "--mode", "1280x480", "--supersampling", "1"})
                  .status,
              0);
    std::filesystem::copy_file(other / "calibration.yaml", dir / "calibration.yaml",
                               std::filesystem::copy_options::overwrite_existing);
    const auto r = runVolume(dir);
    EXPECT_EQ(r.status, kExitDataErr);
    EXPECT_NE(r.err.find("calibration.yaml"), std::string::npos) << r.err;
}

TEST(VolumeCli, MissingDirectoryAndBadArguments) {
    EXPECT_EQ(runVolume("/nonexistent/scene").status, kExitNoInput);
    const auto r = test::runProgram({icewatchBin(), "synth", "--scene", "cone", "--ice-volume-mm3", "1", "--out", "/tmp/x"});
    EXPECT_EQ(r.status, kExitUsage);
}

TEST(VolumeCli, FloorNeedsTheTruthMaps) {
    const auto dir = smallScene();
    const auto r = test::runProgram({icewatchBin(), "floor", "--scene", dir.string(), "--json"});
    EXPECT_EQ(r.status, kExitNoInput);
    EXPECT_NE(r.err.find("truth_disparity_before.pfm"), std::string::npos) << r.err;
}

TEST(VolumeCli, FloorNamesAMissingOrMalformedTruth) {
    const auto dir = smallScene(test::freshTempDir(), true);
    ASSERT_FALSE(HasFailure());
    std::filesystem::rename(dir / "truth.json", dir / "truth.json.away");
    auto r = test::runProgram({icewatchBin(), "floor", "--scene", dir.string(), "--box", "9"});
    EXPECT_EQ(r.status, kExitNoInput);
    EXPECT_NE(r.err.find("truth.json"), std::string::npos) << r.err;
    std::ofstream(dir / "truth.json") << "{\"ice_volume_mm3\": \"lots\"}";
    r = test::runProgram({icewatchBin(), "floor", "--scene", dir.string(), "--box", "9"});
    EXPECT_EQ(r.status, kExitDataErr);
    EXPECT_NE(r.err.find("ice_volume_mm3"), std::string::npos) << r.err;
    std::filesystem::rename(dir / "truth.json.away", dir / "truth.json");
    stereo::writePfm(dir / "truth_ice_mm.pfm", cv::Mat(10, 10, CV_32F, cv::Scalar(0)));
    r = test::runProgram({icewatchBin(), "floor", "--scene", dir.string(), "--box", "9"});
    EXPECT_EQ(r.status, kExitDataErr);
    EXPECT_NE(r.err.find("truth_ice_mm.pfm"), std::string::npos) << r.err;
}

TEST(VolumeCli, FloorCarriesTheImagesNoiseToTheVolume) {
    const auto dir = test::freshTempDir() / "blade";
    const auto rendered = synth(dir, {"--scene", "blade", "--ice-volume-mm3", "97609", "--mode", "1280x480",
                                      "--supersampling", "2", "--truth-maps"});
    ASSERT_EQ(rendered.status, 0) << rendered.err;
    for (const char* name : {"truth_disparity_before.pfm", "truth_disparity_after.pfm", "truth_ice_mm.pfm"}) {
        EXPECT_TRUE(std::filesystem::exists(dir / name)) << name;
    }
    const auto r = test::runProgram({icewatchBin(), "floor", "--scene", dir.string(), "--box", "11", "--json"});
    ASSERT_EQ(r.status, 0) << r.err;
    const auto out = nlohmann::json::parse(r.out);
    EXPECT_GT(out["before"]["boxes"].get<int>(), 10);
    EXPECT_GT(out["before"]["box_sigma_px"].get<double>(), 0.0);
    EXPECT_LT(std::abs(out["after"]["box_mean_px"].get<double>()), 0.05);
    EXPECT_NEAR(out["truth_volume_mm3"].get<double>(), 97609.0, 1e-3);
    // The iced pixels are a part of the object, so the oracle integrating only them sees less noise
    // than integrating the whole object.
    EXPECT_GT(out["iced_pixels"].get<int>(), 0);
    EXPECT_LT(out["iced_pixels"].get<int>(), out["object_pixels"].get<int>());
    EXPECT_GT(out["floor_mm3"].get<double>(), 0.0);
    EXPECT_LT(out["floor_mm3"].get<double>(), out["whole_object_mm3"].get<double>());
    EXPECT_NEAR(out["floor_percent"].get<double>(), 100.0 * out["floor_mm3"].get<double>() / 97609.0, 1e-6);
}

// The rows at the top of a picture where a refusal's reason is written: white letters on dark.
int whitePixelsAtTheTop(const cv::Mat& picture) {
    cv::Mat white;
    cv::inRange(picture(cv::Rect(0, 0, picture.cols, std::min(picture.rows, 30))), cv::Scalar::all(200),
                cv::Scalar::all(255), white);
    return cv::countNonZero(white);
}

TEST(VolumeCli, ARefusedSceneStillWritesItsPicturesWithTheReason) {
    const auto dir = smallScene();
    // A gate no scene passes: the chain refuses after the matcher has seen both captures.
    const auto config = dir.parent_path() / "strict.json";
    std::ofstream(config) << R"({"volume": {"min_points": 100000000}})";
    const auto debug = dir.parent_path() / "debug";
    const auto r = test::runProgram({icewatchBin(), "volume", "--scene", dir.string(), "--stereo-method", "sgbm",
                                     "--config", config.string(), "--json", "--debug-dir", debug.string()});
    ASSERT_EQ(r.status, kExitFailure) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["status"], "refused");
    for (const char* name : {"left.png", "disparity.png", "thickness.png"}) {
        const cv::Mat picture = cv::imread((debug / name).string());
        ASSERT_FALSE(picture.empty()) << name;
        EXPECT_GE(picture.cols, 320) << name;
        EXPECT_GT(whitePixelsAtTheTop(picture), 20) << name << ": the reason is written on it";
    }
    EXPECT_FALSE(std::filesystem::exists(debug / "cloud.ply")) << "no surface was measured against the baseline";
}

TEST(VolumeCli, AMeasuredSceneWritesItsPicturesAndCloud) {
    const auto dir = smallScene();
    const auto debug = dir.parent_path() / "debug";
    const auto r = test::runProgram({icewatchBin(), "volume", "--scene", dir.string(), "--stereo-method", "sgbm",
                                     "--debug-dir", debug.string()});
    ASSERT_EQ(r.status, 0) << r.err << r.out;
    EXPECT_EQ(r.out.rfind("ice volume ", 0), 0u) << "a one-line summary without --json: " << r.out;
    for (const char* name : {"left.png", "disparity.png", "thickness.png", "cloud.ply"}) {
        EXPECT_TRUE(std::filesystem::exists(debug / name)) << name;
    }
    const cv::Mat thickness = cv::imread((debug / "thickness.png").string());
    EXPECT_GT(thickness.cols, 320) << "the picture and its colour bar";
    // The same thickness as numbers, in the left eye's pixels, measured somewhere and NaN elsewhere.
    const cv::Mat thicknessMm = cv::imread((debug / "thickness_mm.pfm").string(), cv::IMREAD_UNCHANGED);
    ASSERT_EQ(thicknessMm.type(), CV_32FC1);
    EXPECT_EQ(thicknessMm.size(), cv::imread((debug / "left.png").string()).size());
    const auto nan = std::count_if(thicknessMm.begin<float>(), thicknessMm.end<float>(), [](float t) { return std::isnan(t); });
    EXPECT_GT(nan, 0) << "NaN outside the region";
    EXPECT_LT(nan, static_cast<long>(thicknessMm.total())) << "measured inside it";
    // Writing into a directory that holds results needs --force.
    const auto again = test::runProgram({icewatchBin(), "volume", "--scene", dir.string(), "--stereo-method", "sgbm",
                                         "--debug-dir", debug.string()});
    EXPECT_EQ(again.status, kExitCantCreate);
    EXPECT_NE(again.err.find("--force"), std::string::npos) << again.err;
    const auto forced = test::runProgram({icewatchBin(), "volume", "--scene", dir.string(), "--stereo-method", "sgbm",
                                          "--debug-dir", debug.string(), "--force"});
    EXPECT_EQ(forced.status, 0) << forced.err;
}

}  // namespace
}  // namespace icewatch
