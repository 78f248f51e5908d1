// icewatch calibrate and icewatch rectify as a person commissioning a box meets them.
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/calib/stereo_calibration.hpp"
#include "core/common/exit_codes.hpp"
#include "core/common/side_by_side.hpp"
#include "tests/support/run_program.hpp"
#include "tests/support/test_paths.hpp"

namespace icewatch {
namespace {

namespace fs = std::filesystem;

std::string icewatchBin() { return (test::binDir() / "icewatch").string(); }

fs::path openCvSet() { return test::sharedData() / "calibration" / "opencv-chessboard-9x6"; }

std::string readText(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

cv::Mat sideBySideFromSet(const std::string& nn) {
    const cv::Mat left = cv::imread((openCvSet() / ("left" + nn + ".jpg")).string(), cv::IMREAD_COLOR);
    const cv::Mat right = cv::imread((openCvSet() / ("right" + nn + ".jpg")).string(), cv::IMREAD_COLOR);
    return joinSideBySide(left, right);
}

nlohmann::json parseJson(const test::ProgramResult& r) {
    try {
        return nlohmann::json::parse(r.out);
    } catch (const nlohmann::json::exception& e) {
        ADD_FAILURE() << "not JSON: " << r.out << "\n" << r.err;
        return {};
    }
}

TEST(CalibrateCli, OpenCvImageListMeetsTargets) {
    const auto dir = test::freshTempDir();
    auto r = test::runProgram({icewatchBin(), "calibrate", "--pairs", (openCvSet() / "stereo_calib.xml").string(),
                               "--board", "9x6", "--square-mm", "1", "--out", (dir / "calibration.yaml").string(),
                               "--json"});
    ASSERT_EQ(r.status, 0) << r.err;
    const nlohmann::json result = parseJson(r);
    EXPECT_LE(result.at("rms_px").get<double>(), 0.5);
    EXPECT_LE(result.at("epipolar_px").get<double>(), 0.5);
    EXPECT_EQ(result.at("pairs_used").get<int>(), 13);
    EXPECT_EQ(result.at("pairs_skipped").get<int>(), 0);
    const calib::StereoCalibration c = calib::loadCalibration(dir / "calibration.yaml");
    EXPECT_EQ(c.imageSize, cv::Size(640, 480));
    EXPECT_NEAR(c.baselineMm(), result.at("baseline_mm").get<double>(), 1e-9);
}

// A recording as `icewatch record` writes it, with one frame where the right eye saw no board.
TEST(CalibrateCli, RecordingDirectorySkipsAndNamesPairsWithoutTheBoard) {
    const auto dir = test::freshTempDir();
    const fs::path recording = dir / "recording";
    fs::create_directories(recording);
    int index = 0;
    auto frameName = [&] {
        char name[16];
        std::snprintf(name, sizeof name, "%06d.jpg", ++index);
        return recording / name;
    };
    for (const char* nn : {"01", "02", "03", "04", "05", "06"}) {
        ASSERT_TRUE(cv::imwrite(frameName().string(), sideBySideFromSet(nn), {cv::IMWRITE_JPEG_QUALITY, 95}));
    }
    cv::Mat blankRight = sideBySideFromSet("07");
    blankRight(cv::Rect(640, 0, 640, 480)).setTo(cv::Scalar(128, 128, 128));
    ASSERT_TRUE(cv::imwrite(frameName().string(), blankRight, {cv::IMWRITE_JPEG_QUALITY, 95}));
    std::ofstream(recording / "recording.json")
        << R"({"device": "fake", "pixel_format": "mjpeg", "width": 1280, "height": 480, "fps": 30, "frames": []})";

    auto r = test::runProgram({icewatchBin(), "calibrate", "--pairs", recording.string(), "--board", "9x6",
                               "--square-mm", "25", "--out", (dir / "calibration.yaml").string(), "--json"});
    ASSERT_EQ(r.status, 0) << r.err;
    const nlohmann::json result = parseJson(r);
    EXPECT_EQ(result.at("pairs_used").get<int>(), 6);
    EXPECT_EQ(result.at("pairs_skipped").get<int>(), 1);
    EXPECT_EQ(result.at("skipped").at(0).at("name"), "000007.jpg");
    EXPECT_NE(result.at("skipped").at(0).at("reason").get<std::string>().find("right eye"), std::string::npos);
    EXPECT_LE(result.at("rms_px").get<double>(), 0.5);
    EXPECT_LE(result.at("epipolar_px").get<double>(), 0.5);
    EXPECT_NE(r.err.find("000007.jpg"), std::string::npos) << "the skipped frame is logged too";
}

// A raw YUYV recording: frames as the camera sent them, the size from recording.json.
TEST(CalibrateCli, RawYuyvRecording) {
    const auto dir = test::freshTempDir();
    const fs::path recording = dir / "recording";
    fs::create_directories(recording);
    int index = 0;
    for (const char* nn : {"01", "03", "06", "09", "12"}) {
        cv::Mat grey;
        cv::cvtColor(sideBySideFromSet(nn), grey, cv::COLOR_BGR2GRAY);
        // Y from the grey image, neutral chroma: Y0 U Y1 V per pixel pair.
        std::vector<unsigned char> yuyv;
        for (int y = 0; y < grey.rows; ++y) {
            for (int x = 0; x < grey.cols; ++x) {
                yuyv.push_back(grey.at<unsigned char>(y, x));
                yuyv.push_back(128);
            }
        }
        char name[16];
        std::snprintf(name, sizeof name, "%06d.yuyv", ++index);
        std::ofstream(recording / name, std::ios::binary)
            .write(reinterpret_cast<const char*>(yuyv.data()), static_cast<std::streamsize>(yuyv.size()));
    }
    std::ofstream(recording / "recording.json")
        << R"({"device": "fake", "pixel_format": "yuyv", "width": 1280, "height": 480, "fps": 30, "frames": []})";
    auto r = test::runProgram({icewatchBin(), "calibrate", "--pairs", recording.string(), "--square-mm", "25",
                               "--out", (dir / "calibration.yaml").string(), "--json"});
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_EQ(parseJson(r).at("pairs_used").get<int>(), 5);

    // A frame cut short is named, not half-used.
    fs::resize_file(recording / "000003.yuyv", 1000);
    auto cut = test::runProgram({icewatchBin(), "calibrate", "--pairs", recording.string(), "--square-mm", "25",
                                 "--out", (dir / "calibration.yaml").string()});
    EXPECT_EQ(cut.status, kExitDataErr);
    EXPECT_NE(cut.err.find("000003.yuyv: 1000 bytes, a 1280x480 YUYV frame has 1228800"), std::string::npos) << cut.err;
}

TEST(CalibrateCli, BadInvocationsExitWithTheirReason) {
    const auto dir = test::freshTempDir();
    const std::string out = (dir / "c.yaml").string();
    auto missing = test::runProgram(
        {icewatchBin(), "calibrate", "--pairs", (dir / "absent").string(), "--square-mm", "1", "--out", out});
    EXPECT_EQ(missing.status, kExitNoInput);
    EXPECT_NE(missing.err.find("absent: no such directory or image list"), std::string::npos) << missing.err;

    auto board = test::runProgram({icewatchBin(), "calibrate", "--pairs", openCvSet().string(), "--board", "9by6",
                                   "--square-mm", "1", "--out", out});
    EXPECT_EQ(board.status, kExitUsage);
    EXPECT_NE(board.err.find("--board"), std::string::npos) << board.err;

    auto square = test::runProgram({icewatchBin(), "calibrate", "--pairs", openCvSet().string(), "--out", out});
    EXPECT_EQ(square.status, kExitUsage);
    EXPECT_NE(square.err.find("--square-mm"), std::string::npos) << square.err;

    auto noDir = test::runProgram({icewatchBin(), "calibrate", "--pairs", openCvSet().string(), "--square-mm", "1",
                                   "--out", (dir / "absent" / "c.yaml").string()});
    EXPECT_EQ(noDir.status, kExitCantCreate);
    EXPECT_NE(noDir.err.find("no directory"), std::string::npos) << noDir.err;

    // Frames without any chessboard: nothing to calibrate from, and every frame is named.
    fs::create_directories(dir / "empty");
    cv::imwrite((dir / "empty" / "000001.png").string(), cv::Mat(60, 160, CV_8UC3, cv::Scalar(50, 60, 70)));
    auto none = test::runProgram(
        {icewatchBin(), "calibrate", "--pairs", (dir / "empty").string(), "--square-mm", "1", "--out", out});
    EXPECT_EQ(none.status, kExitDataErr);
    EXPECT_NE(none.err.find("000001.png: chessboard 9x6 not found in either eye"), std::string::npos) << none.err;
    EXPECT_FALSE(fs::exists(out));
}

// config/calibration/ holds exactly what the documented command writes.
TEST(CalibrateCli, ShippedNominalFilesAreWhatTheCommandWrites) {
    const auto dir = test::freshTempDir();
    for (const char* mode : {"1280x480", "2560x720", "3840x1080", "3840x1520"}) {
        const std::string name = std::string("hbvcam-nominal-") + mode + ".yaml";
        auto r = test::runProgram({icewatchBin(), "calibrate", "--nominal", "--mode", mode, "--out",
                                   (dir / name).string()});
        ASSERT_EQ(r.status, 0) << r.err;
        EXPECT_EQ(readText(dir / name), readText(test::sourceDir() / "config" / "calibration" / name)) << name;
    }
    auto odd = test::runProgram({icewatchBin(), "calibrate", "--nominal", "--mode", "1281x480", "--out",
                                 (dir / "odd.yaml").string()});
    EXPECT_EQ(odd.status, kExitUsage);
}

class RectifyCli : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = test::freshTempDir();
        calibration_ = dir_ / "nominal.yaml";
        calib::saveCalibration(calibration_, calib::nominalCalibration({640, 480}, 80.0, 60.0));
        frame_ = dir_ / "frame.png";
        frameImage_ = sideBySideFromSet("01");
        ASSERT_TRUE(cv::imwrite(frame_.string(), frameImage_));
    }

    test::ProgramResult rectify(const fs::path& calibration, const fs::path& frame) {
        return test::runProgram({icewatchBin(), "rectify", "--calib", calibration.string(), "--frame", frame.string(),
                                 "--out", (dir_ / "out").string()});
    }

    // The nominal calibration with one entry's text replaced.
    fs::path variant(const std::string& name, const std::string& from, const std::string& to) {
        std::string text = readText(calibration_);
        const auto at = text.find(from);
        EXPECT_NE(at, std::string::npos) << from;
        text.replace(at, from.size(), to);
        std::ofstream(dir_ / name) << text;
        return dir_ / name;
    }

    fs::path dir_, calibration_, frame_;
    cv::Mat frameImage_;
};

TEST_F(RectifyCli, WritesBothEyesAndTheLinedPicture) {
    auto r = rectify(calibration_, frame_);
    ASSERT_EQ(r.status, 0) << r.err;
    const cv::Mat left = cv::imread((dir_ / "out" / "left.png").string(), cv::IMREAD_COLOR);
    const cv::Mat right = cv::imread((dir_ / "out" / "right.png").string(), cv::IMREAD_COLOR);
    const cv::Mat lined = cv::imread((dir_ / "out" / "rectified_lines.png").string(), cv::IMREAD_COLOR);
    ASSERT_EQ(left.size(), cv::Size(640, 480));
    ASSERT_EQ(right.size(), cv::Size(640, 480));
    ASSERT_EQ(lined.size(), cv::Size(1280, 480));
    // The nominal camera is already rectified: the eyes come out unchanged.
    EXPECT_EQ(cv::norm(left, frameImage_(cv::Rect(0, 0, 640, 480)), cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(right, frameImage_(cv::Rect(640, 0, 640, 480)), cv::NORM_INF), 0.0);
    // A line every 32 px across both eyes, the image untouched between them.
    for (int y = 32; y < 480; y += 32) {
        const cv::Vec3b a = lined.at<cv::Vec3b>(y, 5), b = lined.at<cv::Vec3b>(y, 1000);
        EXPECT_TRUE(a == cv::Vec3b(0, 255, 0) || a == cv::Vec3b(255, 0, 255)) << y;
        EXPECT_EQ(a, b) << y;
    }
    EXPECT_EQ(cv::norm(lined(cv::Rect(0, 33, 1280, 31)), frameImage_(cv::Rect(0, 33, 1280, 31)), cv::NORM_INF), 0.0);
    // Once written, the pictures are not overwritten without --force.
    r = rectify(calibration_, frame_);
    EXPECT_EQ(r.status, kExitCantCreate);
    EXPECT_NE(r.err.find("--force"), std::string::npos) << r.err;
    r = test::runProgram({icewatchBin(), "rectify", "--calib", calibration_.string(), "--frame", frame_.string(), "--out",
                          (dir_ / "out").string(), "--force"});
    EXPECT_EQ(r.status, 0) << r.err;
}

TEST_F(RectifyCli, RefusesAFrameOfTheWrongSize) {
    auto r = rectify(calibration_, test::sharedData() / "middlebury" / "cones" / "left.png");
    EXPECT_EQ(r.status, kExitDataErr);
    EXPECT_NE(r.err.find("left.png: frame is 450x375, but"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("eyes of 640x480"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "out" / "left.png"));
}

TEST_F(RectifyCli, MissingInputsExit66) {
    auto noFrame = rectify(calibration_, dir_ / "absent.jpg");
    EXPECT_EQ(noFrame.status, kExitNoInput);
    EXPECT_NE(noFrame.err.find("absent.jpg: image not found"), std::string::npos) << noFrame.err;
    auto noCalibration = rectify(dir_ / "absent.yaml", frame_);
    EXPECT_EQ(noCalibration.status, kExitNoInput);
    EXPECT_NE(noCalibration.err.find("absent.yaml: calibration file not found"), std::string::npos) << noCalibration.err;
}

TEST_F(RectifyCli, MalformedCalibrationNamesFileAndEntry) {
    struct Case {
        fs::path file;
        std::string expected;
    };
    const Case cases[] = {
        {variant("missing.yaml", "D2:", "X2:"), "missing.yaml: D2: missing"},
        {variant("shape.yaml", "R: !!opencv-matrix\n   rows: 3\n   cols: 3",
                 "R: !!opencv-matrix\n   rows: 1\n   cols: 9"),
         "shape.yaml: R: must be 3x3, got 1x9"},
        {variant("count.yaml", "T: !!opencv-matrix\n   rows: 3", "T: !!opencv-matrix\n   rows: 2"),
         "count.yaml: T: data holds 3 numbers, 2x1 needs 2"},
        {variant("text.yaml", "data: [ 3.8", "data: [ abc"), "text.yaml: M1: data[0] is not a number"},
        {variant("width.yaml", "image_width: 640", "image_width: wide"), "width.yaml: image_width: must be an integer"},
        {variant("focal.yaml", "data: [ 3.8", "data: [ -3.8"), "focal.yaml: M1: focal lengths must be positive"},
    };
    for (const Case& c : cases) {
        auto r = rectify(c.file, frame_);
        EXPECT_EQ(r.status, kExitDataErr) << c.file;
        EXPECT_NE(r.err.find(c.expected), std::string::npos) << r.err;
    }
}

}  // namespace
}  // namespace icewatch
