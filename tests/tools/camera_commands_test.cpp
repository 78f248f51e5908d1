// icewatch info, record and acquire against the fake camera, as a person or a script runs them.
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/common/exit_codes.hpp"
#include "drivers/v4l2/recording.hpp"
#include "tests/drivers/v4l2/test_recording.hpp"
#include "tests/support/run_program.hpp"
#include "tests/support/test_paths.hpp"

namespace icewatch {
namespace {

std::string icewatchBin() { return (test::binDir() / "icewatch").string(); }

std::string demoDevice() { return "fake:" + (test::sourceDir() / "tools/demo/recording").string(); }

TEST(InfoCommand, ListsWhatTheFakeCameraOffers) {
    const auto r = test::runProgram({icewatchBin(), "info", "--device", demoDevice(), "--json"});
    ASSERT_EQ(r.status, 0) << r.err;
    const auto info = nlohmann::json::parse(r.out);
    EXPECT_EQ(info["driver"], "uvcvideo");
    EXPECT_TRUE(info["video_capture"].get<bool>());
    ASSERT_EQ(info["formats"].size(), 2u);
    EXPECT_EQ(info["formats"][0]["fourcc"], "MJPG");
    EXPECT_EQ(info["formats"][0]["sizes"][1]["width"], 2560);
    EXPECT_EQ(info["formats"][0]["sizes"][3]["fps"][0], 10.0);
    bool exposure = false;
    for (const auto& c : info["controls"]) exposure |= c["name"] == "exposure_time_absolute";
    EXPECT_TRUE(exposure);
    const auto text = test::runProgram({icewatchBin(), "info", "--device", demoDevice()});
    EXPECT_EQ(text.status, 0);
    EXPECT_NE(text.out.find("3840x1520 fps: 10 5"), std::string::npos) << text.out;
}

TEST(InfoCommand, NamesAMissingOrWrongDevice) {
    const auto missing = test::runProgram({icewatchBin(), "info", "--device", "/dev/v4l/by-id/usb-none-video-index0"});
    EXPECT_EQ(missing.status, kExitUnavailable);
    EXPECT_NE(missing.err.find("usb-none-video-index0"), std::string::npos);
    const auto notVideo = test::runProgram({icewatchBin(), "info", "--device", "/dev/null"});
    EXPECT_EQ(notVideo.status, kExitUnavailable);
    EXPECT_NE(notVideo.err.find("not a V4L2 device"), std::string::npos);
}

void expectSameFrames(const v4l2::Recording& a, const v4l2::Recording& b) {
    EXPECT_EQ(a.format, b.format);
    EXPECT_EQ(a.width, b.width);
    EXPECT_EQ(a.height, b.height);
    EXPECT_EQ(a.fps, b.fps);
    ASSERT_EQ(a.frames.size(), b.frames.size());
    for (std::size_t i = 0; i < a.frames.size(); ++i) {
        EXPECT_EQ(a.frames[i].timestampUs, b.frames[i].timestampUs) << "frame " << i;
        EXPECT_EQ(a.readFrame(i), b.readFrame(i)) << "frame " << i;
    }
}

TEST(RecordCommand, WritesWhatTheCameraSentAndItReplaysIdentically) {
    const auto dir = test::freshTempDir();
    const v4l2::Recording source = test::makeMjpegRecording(dir / "source", 5);
    const auto first = test::runProgram({icewatchBin(), "record", "--device", "fake:" + (dir / "source").string(),
                                         "--mode", "1280x480", "--format", "mjpeg", "--frames", "5", "--out",
                                         (dir / "first").string(), "--json"});
    ASSERT_EQ(first.status, 0) << first.err;
    EXPECT_EQ(nlohmann::json::parse(first.out)["frames"], 5);
    const v4l2::Recording recorded = v4l2::readRecording(dir / "first");
    expectSameFrames(source, recorded);
    // A recording made by record, replayed and recorded again, is the same recording.
    const auto second = test::runProgram({icewatchBin(), "record", "--device", "fake:" + (dir / "first").string(),
                                          "--mode", "1280x480", "--format", "mjpeg", "--frames", "5", "--out",
                                          (dir / "second").string()});
    ASSERT_EQ(second.status, 0) << second.err;
    expectSameFrames(recorded, v4l2::readRecording(dir / "second"));
    // It never overwrites a recording: not without --force, which allows other files only.
    const auto again = test::runProgram({icewatchBin(), "record", "--device", "fake:" + (dir / "source").string(),
                                         "--mode", "1280x480", "--frames", "1", "--out", (dir / "first").string()});
    EXPECT_EQ(again.status, kExitCantCreate);
    EXPECT_NE(again.err.find("--force"), std::string::npos) << again.err;
    const auto forced = test::runProgram({icewatchBin(), "record", "--device", "fake:" + (dir / "source").string(),
                                          "--mode", "1280x480", "--frames", "1", "--out", (dir / "first").string(),
                                          "--force"});
    EXPECT_EQ(forced.status, kExitCantCreate);
    EXPECT_EQ(v4l2::readRecording(dir / "first").frames.size(), 5u);
    std::filesystem::create_directories(dir / "notes");
    std::ofstream(dir / "notes" / "site.txt") << "tower 7\n";
    EXPECT_EQ(test::runProgram({icewatchBin(), "record", "--device", "fake:" + (dir / "source").string(), "--mode",
                                "1280x480", "--frames", "1", "--out", (dir / "notes").string()})
                  .status,
              kExitCantCreate);
    EXPECT_EQ(test::runProgram({icewatchBin(), "record", "--device", "fake:" + (dir / "source").string(), "--mode",
                                "1280x480", "--frames", "1", "--out", (dir / "notes").string(), "--force"})
                  .status,
              0);
}

TEST(RecordCommand, RefusesABadMode) {
    const auto r = test::runProgram({icewatchBin(), "record", "--device", demoDevice(), "--mode", "wide", "--out",
                                     (test::freshTempDir() / "x").string()});
    EXPECT_EQ(r.status, kExitUsage);
    EXPECT_NE(r.err.find("--mode"), std::string::npos);
}

TEST(AcquireCommand, ReportsTheAcquisitionOfTheDemoRecording) {
    const auto r = test::runProgram({icewatchBin(), "acquire", "--device", demoDevice(), "--frames", "3", "--json"});
    ASSERT_EQ(r.status, 0) << r.err;
    const auto result = nlohmann::json::parse(r.out);
    EXPECT_EQ(result["frames"], 3);
    EXPECT_EQ(result["eye"]["width"], 1280);
    EXPECT_EQ(result["eye"]["height"], 720);
    EXPECT_EQ(result["negotiated"]["width"], 2560);
    EXPECT_EQ(result["negotiated"]["format"], "mjpeg");
    EXPECT_FALSE(result["negotiated"]["substituted"].get<bool>());
    EXPECT_EQ(result["dropped"]["total"], 0);
    EXPECT_TRUE(result["timing"].contains("decode_ms_mean"));
}

TEST(AcquireCommand, ExitStatusSaysWhatKindOfFailure) {
    const auto dir = test::freshTempDir();
    std::ofstream(dir / "c.json") << R"({"camera": {"device": ")" << demoDevice()
                                  << R"(", "controls": {"exposure": 10}}})";
    const auto badControl = test::runProgram({icewatchBin(), "acquire", "--config", (dir / "c.json").string()});
    EXPECT_EQ(badControl.status, kExitConfig);
    EXPECT_NE(badControl.err.find("camera.controls.exposure"), std::string::npos) << badControl.err;
    const auto missing = test::runProgram(
        {icewatchBin(), "acquire", "--device", "/dev/v4l/by-id/usb-none-video-index0", "--timeout-s", "0.1"});
    EXPECT_EQ(missing.status, kExitUnavailable);
}

}  // namespace
}  // namespace icewatch
