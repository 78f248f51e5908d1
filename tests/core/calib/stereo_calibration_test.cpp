#include "core/calib/stereo_calibration.hpp"

#include <fstream>
#include <tuple>

#include <gtest/gtest.h>

#include "core/common/error.hpp"
#include "tests/support/test_paths.hpp"

namespace icewatch::calib {
namespace {

std::string loadError(const std::filesystem::path& path) {
    try {
        loadCalibration(path);
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

TEST(StereoCalibration, NominalHbvcamGeometry) {
    const StereoCalibration c = nominalCalibration({1280, 720}, 80.0, 60.0);
    // HBVCAM.md: f = 763 px at 1280 px per eye and 80° HFOV.
    EXPECT_NEAR(c.M1.at<double>(0, 0), 762.8, 0.5);
    EXPECT_NEAR(c.baselineMm(), 60.0, 1e-9);
    EXPECT_NEAR(c.rectifiedFocalPx(), 762.8, 1.0);
    // Z = f·B/d through Q: a point at 850 mm shows ~54 px of disparity.
    const double d = c.rectifiedFocalPx() * 60.0 / 850.0;
    EXPECT_NEAR(d, 53.8, 0.3);
    cv::Mat point = (cv::Mat_<double>(4, 1) << 640, 360, d, 1);
    cv::Mat xyzw = c.Q * point;
    EXPECT_NEAR(xyzw.at<double>(2) / xyzw.at<double>(3), 850.0, 0.5);
}

TEST(StereoCalibration, SaveLoadRoundTrip) {
    const auto dir = test::freshTempDir();
    const StereoCalibration c = nominalCalibration({640, 480}, 72.0, 60.0);
    saveCalibration(dir / "calibration.yaml", c);
    const StereoCalibration back = loadCalibration(dir / "calibration.yaml");
    EXPECT_EQ(back.imageSize, c.imageSize);
    EXPECT_EQ(cv::norm(back.M1, c.M1, cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(back.T, c.T, cv::NORM_INF), 0.0);
    EXPECT_LT(cv::norm(back.Q, c.Q, cv::NORM_INF), 1e-9);
}

TEST(StereoCalibration, BadFilesNameTheEntry) {
    const auto dir = test::freshTempDir();
    EXPECT_EQ(loadError(dir / "absent.yaml"), (dir / "absent.yaml").string() + ": calibration file not found");

    const StereoCalibration c = nominalCalibration({640, 480}, 72.0, 60.0);
    saveCalibration(dir / "good.yaml", c);
    std::ifstream in(dir / "good.yaml");
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());

    auto writeVariant = [&](const std::string& name, const std::string& from, const std::string& to) {
        std::string changed = text;
        const auto at = changed.find(from);
        EXPECT_NE(at, std::string::npos) << from;
        changed.replace(at, from.size(), to);
        std::ofstream(dir / name) << changed;
        return dir / name;
    };
    // No M1 at all.
    EXPECT_NE(loadError(writeVariant("nom1.yaml", "M1:", "X1:")).find(": M1: missing"), std::string::npos);
    // T as a 2x1 matrix.
    EXPECT_NE(loadError(writeVariant("shape.yaml", "T: !!opencv-matrix\n   rows: 3",
                                     "T: !!opencv-matrix\n   rows: 2"))
                  .find(": T: "),
              std::string::npos);
    // A non-numeric image width.
    EXPECT_NE(loadError(writeVariant("width.yaml", "image_width: 640", "image_width: wide"))
                  .find("image_width: must be an integer"),
              std::string::npos);
    // Not YAML at all.
    std::ofstream(dir / "junk.yaml") << "\x01\x02 this is not a calibration";
    EXPECT_FALSE(loadError(dir / "junk.yaml").empty());
}

// config/calibration/ carries the nominal HBVCAM model for every supported side-by-side mode.
// Files that hung OpenCV's FileStorage (hang.yaml: at 100 % CPU for ever) or escaped as "internal
// error" (exit 70): each is now a data error (65) naming the file. A hang fails by the test timeout.
TEST(StereoCalibration, TheAuditsMalformedFilesAreDataErrors) {
    const auto dir = test::sourceDir() / "tests/core/calib/bad-inputs";
    for (const char* name : {"hang.yaml", "length_error.yaml", "sequence.yaml", "not_a_map.yaml"}) {
        try {
            loadCalibration(dir / name);
            ADD_FAILURE() << name << " loaded";
        } catch (const Error& e) {
            EXPECT_EQ(e.code(), kExitDataErr) << name << ": " << e.what();
            EXPECT_EQ(std::string(e.what()).rfind((dir / name).string() + ": ", 0), 0u) << e.what();
        }
    }
    try {
        loadCalibration(dir / "sequence.yaml");
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("top level: must be a map"), std::string::npos) << e.what();
    }
}

TEST(StereoCalibration, ShippedNominalFilesMatchTheModel) {
    const std::pair<const char*, cv::Size> modes[] = {
        {"1280x480", {640, 480}}, {"2560x720", {1280, 720}}, {"3840x1080", {1920, 1080}}, {"3840x1520", {1920, 1520}}};
    for (const auto& [mode, eye] : modes) {
        const auto file = test::sourceDir() / "config" / "calibration" / (std::string("hbvcam-nominal-") + mode + ".yaml");
        const StereoCalibration shipped = loadCalibration(file);
        const StereoCalibration model = nominalCalibration(eye, 80.0, 60.0);
        EXPECT_EQ(shipped.imageSize, eye) << mode;
        for (const auto& [name, a, b] : {std::tuple{"M1", shipped.M1, model.M1}, std::tuple{"M2", shipped.M2, model.M2},
                                         std::tuple{"D1", shipped.D1, model.D1}, std::tuple{"D2", shipped.D2, model.D2},
                                         std::tuple{"R", shipped.R, model.R}, std::tuple{"T", shipped.T, model.T},
                                         std::tuple{"P1", shipped.P1, model.P1}, std::tuple{"P2", shipped.P2, model.P2},
                                         std::tuple{"Q", shipped.Q, model.Q}}) {
            EXPECT_LT(cv::norm(a, b, cv::NORM_INF), 1e-9) << mode << " " << name;
        }
        EXPECT_NEAR(shipped.baselineMm(), 60.0, 1e-12) << mode;
    }
}

TEST(StereoCalibration, ValidationNamesBadDerivedEntries) {
    StereoCalibration c = nominalCalibration({640, 480}, 80.0, 60.0);
    c.P2.at<double>(0, 0) = -1;
    try {
        validateCalibration(c, "memory");
        FAIL() << "a negative rectified focal length must be refused";
    } catch (const Error& e) {
        EXPECT_STREQ(e.what(), "memory: P2: focal lengths must be positive");
    }
    c = nominalCalibration({640, 480}, 80.0, 60.0);
    c.R1.at<double>(0, 0) = 2;
    EXPECT_THROW(validateCalibration(c, "memory"), Error);
    c = nominalCalibration({640, 480}, 80.0, 60.0);
    c.imageSize.width = 100000;
    EXPECT_THROW(validateCalibration(c, "memory"), Error);
}

TEST(StereoCalibration, SaveReplacesTheFileWholeAndKeepsTheComment) {
    const auto dir = test::freshTempDir();
    saveCalibration(dir / "c.yaml", nominalCalibration({640, 480}, 80.0, 60.0), "first line\nsecond line");
    saveCalibration(dir / "c.yaml", nominalCalibration({1280, 720}, 80.0, 60.0), "replaced");
    EXPECT_EQ(loadCalibration(dir / "c.yaml").imageSize, cv::Size(1280, 720));
    std::ifstream in(dir / "c.yaml");
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find("# replaced\n"), std::string::npos);
    EXPECT_EQ(text.find("first line"), std::string::npos);
    // Nothing is left beside it.
    EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir), std::filesystem::directory_iterator()), 1);
    EXPECT_THROW(saveCalibration(dir / "missing-dir" / "c.yaml", nominalCalibration({640, 480}, 80.0, 60.0)), Error);
}

TEST(Rectifier, IdentityForNominalPairAndSizeCheck) {
    const StereoCalibration c = nominalCalibration({64, 48}, 80.0, 60.0);
    Rectifier rectifier(c);
    StereoPair pair{cv::Mat(48, 64, CV_8UC3), cv::Mat(48, 64, CV_8UC3)};
    cv::randu(pair.left, 0, 255);
    cv::randu(pair.right, 0, 255);
    const StereoPair out = rectifier.rectify(pair);
    // An ideal, already rectified pair maps onto itself.
    EXPECT_EQ(cv::norm(out.left, pair.left, cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(out.right, pair.right, cv::NORM_INF), 0.0);
    StereoPair wrong{cv::Mat(48, 60, CV_8UC3), cv::Mat(48, 60, CV_8UC3)};
    EXPECT_THROW(rectifier.rectify(wrong), InvalidInput);
    EXPECT_NO_THROW(checkFrameSize(c, {128, 48}, "c.yaml"));
    try {
        checkFrameSize(c, {120, 48}, "c.yaml");
        FAIL() << "a frame of the wrong size must be refused";
    } catch (const InvalidInput& e) {
        EXPECT_STREQ(e.what(), "frame is 120x48, but c.yaml is for eyes of 64x48 (a 128x48 side-by-side frame)");
    }
}

// Keeping the maps of one box (the chain's region) rectifies that box exactly as the whole maps
// do; a box outside it is refused until focus() builds the whole maps again, which then give the
// same pixels once more. A distorted, rotated calibration, so that the maps are not the identity.
TEST(Rectifier, FocusedMapsGiveTheSamePixels) {
    StereoCalibration c = nominalCalibration({96, 64}, 80.0, 60.0);
    c.D1 = (cv::Mat_<double>(1, 5) << -0.2, 0.05, 0.001, -0.002, 0.0);
    c.D2 = (cv::Mat_<double>(1, 5) << 0.1, -0.03, 0.0, 0.001, 0.0);
    c.R = (cv::Mat_<double>(3, 3) << 0.9998, -0.02, 0.0, 0.02, 0.9998, 0.0, 0.0, 0.0, 1.0);
    c.R1 = c.R2 = c.P1 = c.P2 = c.Q = cv::Mat();
    Rectifier rectifier(c);
    StereoPair pair{cv::Mat(64, 96, CV_8UC3), cv::Mat(64, 96, CV_8UC3)};
    cv::randu(pair.left, 0, 255);
    cv::randu(pair.right, 0, 255);
    const StereoPair whole = rectifier.rectify(pair);
    const cv::Rect box(20, 10, 50, 30), inner(25, 12, 20, 20), outside(0, 0, 40, 40);
    rectifier.focus(box);
    EXPECT_EQ(rectifier.mapped(), box);
    for (const cv::Rect& r : {box, inner}) {
        const StereoPair part = rectifier.rectify(pair, r);
        EXPECT_EQ(cv::norm(part.left, whole.left(r), cv::NORM_INF), 0.0);
        EXPECT_EQ(cv::norm(part.right, whole.right(r), cv::NORM_INF), 0.0);
    }
    EXPECT_THROW(rectifier.rectify(pair, outside), InvalidInput);
    EXPECT_THROW(rectifier.rectify(pair), InvalidInput);
    rectifier.focus(outside);
    const StereoPair again = rectifier.rectify(pair, outside);
    EXPECT_EQ(cv::norm(again.left, whole.left(outside), cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(again.right, whole.right(outside), cv::NORM_INF), 0.0);
    EXPECT_THROW(rectifier.focus(cv::Rect(90, 0, 10, 10)), InvalidInput);
}

}  // namespace
}  // namespace icewatch::calib
