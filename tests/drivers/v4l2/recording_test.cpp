// Recordings: written and read back unchanged, and a damaged one is refused naming what is wrong.
#include "drivers/v4l2/recording.hpp"

#include <fstream>

#include <gtest/gtest.h>

#include "core/common/error.hpp"
#include "tests/drivers/v4l2/test_recording.hpp"
#include "tests/support/test_paths.hpp"

namespace icewatch::v4l2 {
namespace {

void expectRefused(const std::filesystem::path& dir, int code, const std::string& words) {
    try {
        readRecording(dir);
        ADD_FAILURE() << "accepted a recording that should be refused for: " << words;
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), code) << e.what();
        EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
}

void rewriteIndex(const std::filesystem::path& dir, const std::string& from, const std::string& to) {
    std::ifstream in(dir / "recording.json");
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const auto at = text.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
    std::ofstream(dir / "recording.json") << text;
}

TEST(Recording, WritesAndReadsBackFramesAndTimestamps) {
    const auto dir = test::freshTempDir() / "rec";
    const Recording r = test::makeMjpegRecording(dir, 3, 64, 48);
    EXPECT_EQ(r.format, PixelFormat::kMjpeg);
    EXPECT_EQ(r.width, 128);
    EXPECT_EQ(r.height, 48);
    ASSERT_EQ(r.frames.size(), 3u);
    EXPECT_EQ(r.frames[0].timestampUs, 0);  // relative to the first frame
    EXPECT_EQ(r.frames[2].timestampUs, 66666);
    EXPECT_EQ(r.framePath(0).filename(), "000001.jpg");
    EXPECT_EQ(r.readFrame(1).size(), r.frames[1].bytes);
    const Recording y = test::makeYuyvRecording(test::freshTempDir() / "yuyv", 1, 8, 4);
    EXPECT_EQ(y.framePath(0).filename(), "000001.yuyv");
    EXPECT_EQ(y.frames[0].bytes, 16u * 4u * 2u);
}

TEST(Recording, RefusesDamageNamingTheFileKeyAndFrame) {
    const auto base = test::freshTempDir();
    auto fresh = [&](const std::string& name) {
        const auto dir = base / name;
        test::makeMjpegRecording(dir, 3, 64, 48);
        return dir;
    };
    expectRefused(base / "absent", kExitNoInput, "recording.json: cannot read");
    auto dir = fresh("missing-frame");
    std::filesystem::remove(dir / "000002.jpg");
    expectRefused(dir, kExitNoInput, "000002.jpg: frame 2 is missing");
    dir = fresh("short-frame");
    std::filesystem::resize_file(dir / "000003.jpg", 10);
    expectRefused(dir, kExitDataErr, "000003.jpg: frame 3 has 10 bytes");
    dir = fresh("format");
    rewriteIndex(dir, "\"mjpeg\"", "\"h264\"");
    expectRefused(dir, kExitDataErr, "pixel_format: must be mjpeg or yuyv");
    dir = fresh("width");
    rewriteIndex(dir, "\"width\": 128", "\"width\": 127");
    expectRefused(dir, kExitDataErr, "width: must be even");
    dir = fresh("time");
    rewriteIndex(dir, "\"timestamp_us\": 66666", "\"timestamp_us\": 5");
    expectRefused(dir, kExitDataErr, "frames[2].timestamp_us: goes backwards");
    dir = fresh("json");
    std::ofstream(dir / "recording.json") << "{ not json";
    expectRefused(dir, kExitDataErr, "not valid JSON");
}

TEST(Recording, WriterRefusesToOverwriteARecording) {
    const auto dir = test::freshTempDir() / "rec";
    test::makeMjpegRecording(dir, 1, 64, 48);
    EXPECT_THROW(RecordingWriter(dir, "x", PixelFormat::kMjpeg, 128, 48, 30), Error);
}

}  // namespace
}  // namespace icewatch::v4l2
