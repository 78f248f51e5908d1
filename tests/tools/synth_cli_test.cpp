// icewatch synth as the benchmark and the tests run it: what it writes and how it refuses.
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "core/common/exit_codes.hpp"
#include "drivers/v4l2/recording.hpp"
#include "tests/support/run_program.hpp"
#include "tests/support/test_paths.hpp"

namespace icewatch {
namespace {

namespace fs = std::filesystem;

// icewatch synth on a small, fast blade with these extra arguments, written into dir.
test::ProgramResult synth(const fs::path& dir, std::vector<std::string> extra) {
    std::vector<std::string> arguments{(test::binDir() / "icewatch").string(), "synth", "--scene", "blade",
                                       "--ice-volume-mm3", "97609", "--mode", "640x240", "--supersampling", "1",
                                       "--out", dir.string()};
    arguments.insert(arguments.end(), extra.begin(), extra.end());
    return test::runProgram(arguments);
}

nlohmann::json truth(const fs::path& dir) {
    std::ifstream in(dir / "truth.json");
    return nlohmann::json::parse(in);
}

TEST(SynthCli, FramesWriteRecordingsTheRecorderReads) {
    const fs::path dir = test::freshTempDir() / "scene";
    const auto r = synth(dir, {"--frames", "3"});
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_FALSE(fs::exists(dir / "before.png"));
    EXPECT_FALSE(fs::exists(dir / "after.png"));
    for (const char* capture : {"before", "after"}) {
        const v4l2::Recording recording = v4l2::readRecording(dir / capture);
        EXPECT_EQ(recording.device, "synth");
        EXPECT_EQ(recording.format, v4l2::PixelFormat::kMjpeg);
        EXPECT_EQ(recording.width, 640);
        EXPECT_EQ(recording.height, 240);
        EXPECT_EQ(recording.fps, 30);
        ASSERT_EQ(recording.frames.size(), 3u);
        EXPECT_EQ(recording.frames[0].timestampUs, 0);
        EXPECT_EQ(recording.frames[1].timestampUs, 33333);
        EXPECT_EQ(recording.frames[2].timestampUs, 66667);
        std::vector<cv::Mat> frames;
        for (std::size_t k = 0; k < recording.frames.size(); ++k) {
            frames.push_back(cv::imdecode(recording.readFrame(k), cv::IMREAD_COLOR));
            ASSERT_EQ(frames.back().size(), cv::Size(640, 240)) << capture << " frame " << k + 1;
        }
        EXPECT_GT(cv::norm(frames[0], frames[1], cv::NORM_L1), 0.0) << capture << ": the noise must differ";
    }
    EXPECT_EQ(truth(dir)["frames"], 3);
}

TEST(SynthCli, RenderingAgainReplacesTheOtherKindOfCapture) {
    const fs::path dir = test::freshTempDir() / "scene";
    ASSERT_EQ(synth(dir, {"--frames", "2"}).status, 0);
    ASSERT_EQ(synth(dir, {"--force"}).status, 0);
    EXPECT_TRUE(fs::exists(dir / "before.png"));
    EXPECT_FALSE(fs::exists(dir / "before"));
    EXPECT_FALSE(fs::exists(dir / "after"));
    ASSERT_EQ(synth(dir, {"--frames", "2", "--force"}).status, 0);
    EXPECT_FALSE(fs::exists(dir / "before.png"));
    EXPECT_EQ(v4l2::readRecording(dir / "after").frames.size(), 2u);
}

TEST(SynthCli, AnExistingSceneIsNotOverwrittenWithoutForce) {
    const fs::path dir = test::freshTempDir() / "scene";
    ASSERT_EQ(synth(dir, {}).status, 0);
    const auto written = fs::last_write_time(dir / "before.png");
    const auto again = synth(dir, {"--seed", "5"});
    EXPECT_EQ(again.status, kExitCantCreate);
    EXPECT_NE(again.err.find("--force"), std::string::npos) << again.err;
    EXPECT_EQ(fs::last_write_time(dir / "before.png"), written);
    EXPECT_EQ(truth(dir)["seed"], 1);
    // An empty directory is no scene to lose.
    const fs::path empty = test::freshTempDir() / "empty";
    fs::create_directories(empty);
    EXPECT_EQ(synth(empty, {}).status, 0);
}

TEST(SynthCli, PrintsASummaryOrJson) {
    const fs::path base = test::freshTempDir();
    const auto human = synth(base / "a", {});
    ASSERT_EQ(human.status, 0) << human.err;
    EXPECT_NE(human.out.find("wrote a blade scene of 97609 mm3"), std::string::npos) << human.out;
    EXPECT_EQ(human.err.find('\r'), std::string::npos) << "no progress line when stderr is not a terminal";
    const auto json = synth(base / "b", {"--json"});
    ASSERT_EQ(json.status, 0) << json.err;
    EXPECT_NEAR(nlohmann::json::parse(json.out)["ice_volume_mm3"].get<double>(), 97609.0, 0.5);
}

TEST(SynthCli, ShowsProgressOnATerminal) {
    // script(1) gives the command a terminal; its screen is script's output.
    if (!fs::exists("/usr/bin/script")) GTEST_SKIP() << "no script(1)";
    const fs::path dir = test::freshTempDir() / "scene";
    const std::string command = (test::binDir() / "icewatch").string() +
                                " synth --scene block --ice-volume-mm3 1000 --mode 320x120 --supersampling 1 --out " +
                                dir.string();
    const auto r = test::runProgram({"/usr/bin/script", "-qec", command, "/dev/null"});
    ASSERT_EQ(r.status, 0) << r.err << r.out;
    EXPECT_NE(r.out.find("synth: rendering 320x120"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("wrote a block scene"), std::string::npos) << r.out;
}

TEST(SynthCli, BadFrameCountIsAUsageError) {
    const fs::path base = test::freshTempDir();
    for (const char* frames : {"0", "257", "many"}) {
        const auto r = synth(base / frames, {"--frames", frames});
        EXPECT_EQ(r.status, kExitUsage) << frames;
        EXPECT_NE(r.err.find("--frames"), std::string::npos) << r.err;
        EXPECT_FALSE(fs::exists(base / frames / "truth.json"));
    }
}

TEST(SynthCli, TruthRecordsEveryOption) {
    const fs::path dir = test::freshTempDir() / "scene";
    const auto r = synth(dir, {"--ice", "patches", "--motion", "none", "--background", "table", "--light-change", "0.85",
                               "--shadows", "--table-gap-mm", "6", "--blur-px", "0.8", "--tone-curve", "filmic",
                               "--truth-maps"});
    ASSERT_EQ(r.status, 0) << r.err;
    const nlohmann::json t = truth(dir);
    EXPECT_EQ(t["scene"], "blade");
    EXPECT_EQ(t["ice"], "patches");
    EXPECT_EQ(t["motion"], "none");
    EXPECT_EQ(t["background"], "table");
    EXPECT_DOUBLE_EQ(t["light_change"].get<double>(), 0.85);
    EXPECT_EQ(t["shadows"], true);
    EXPECT_DOUBLE_EQ(t["table_gap_mm"].get<double>(), 6.0);
    EXPECT_EQ(t["ice_over_edges"], false);
    EXPECT_DOUBLE_EQ(t["blur_px"].get<double>(), 0.8);
    EXPECT_EQ(t["tone_curve"], "filmic");
    EXPECT_EQ(t["frames"], 1);
    EXPECT_EQ(t["supersampling"], 1);
    EXPECT_EQ(t["mode"], "640x240");
    EXPECT_NEAR(t["ice_volume_mm3"].get<double>(), 97609.0, 1e-6 * 97609.0);
    EXPECT_EQ(t["motion_translation_mm"], nlohmann::json({0.0, 0.0, 0.0}));
    // The pivot of the (here null) motion is where the object stands, about a metre away.
    ASSERT_EQ(t["motion_pivot_mm"].size(), 3u);
    EXPECT_GT(t["motion_pivot_mm"][2].get<double>(), 500.0);
    EXPECT_TRUE(t["look"]["composite_contrast"].is_number());
    for (const char* name : {"before.png", "after.png", "truth_disparity_before.pfm", "truth_disparity_after.pfm",
                             "truth_ice_mm.pfm"}) {
        EXPECT_TRUE(fs::exists(dir / name)) << name;
    }
}

TEST(SynthCli, BadOptionValuesAreUsageErrors) {
    const fs::path base = test::freshTempDir();
    const std::vector<std::vector<std::string>> bad{
        {"--ice", "frost"},          {"--motion", "huge"},        {"--background", "sea"},
        {"--light-change", "0.1"},   {"--light-change", "3.5"},   {"--light-change", "bright"},
        {"--table-gap-mm", "150"},   {"--blur-px", "6"},          {"--tone-curve", "log"}};
    int k = 0;
    for (const auto& arguments : bad) {
        const fs::path dir = base / std::to_string(k++);
        const auto r = synth(dir, arguments);
        EXPECT_EQ(r.status, kExitUsage) << arguments[0] << " " << arguments[1];
        const std::string& option = arguments[arguments.size() - 2];
        EXPECT_NE(r.err.find(option), std::string::npos) << r.err;
        EXPECT_FALSE(fs::exists(dir / "truth.json"));
    }
    const auto block = test::runProgram({(test::binDir() / "icewatch").string(), "synth", "--scene", "block",
                                         "--ice-volume-mm3", "1000", "--ice", "glaze-all", "--out",
                                         (base / "block").string()});
    EXPECT_EQ(block.status, kExitUsage);
    EXPECT_NE(block.err.find("--ice"), std::string::npos) << block.err;
    // Rime patches end where they end: only a glaze-all blade's ice is grown over its edges.
    const auto patches = synth(base / "patches", {"--ice", "patches", "--ice-over-edges"});
    EXPECT_EQ(patches.status, kExitUsage);
    EXPECT_NE(patches.err.find("--ice-over-edges"), std::string::npos) << patches.err;
    EXPECT_FALSE(fs::exists(base / "patches" / "truth.json"));
}

}  // namespace
}  // namespace icewatch
