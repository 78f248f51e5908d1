// icewatch match / eval / bench as a person or a script meets them: outputs, JSON, exit statuses.
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/common/exit_codes.hpp"
#include "core/stereo/disparity_io.hpp"
#include "core/stereo/matcher.hpp"
#include "tests/support/run_program.hpp"
#include "tests/support/test_paths.hpp"

namespace icewatch {
namespace {

std::string icewatchBin() { return (test::binDir() / "icewatch").string(); }

struct SmallPair {
    std::string left, right, gt, mask;
};

// A textured pair shifted by 6 px with its ground truth (scale 4) and a full mask.
SmallPair writeSmallPair(const std::filesystem::path& dir) {
    cv::Mat texture(48, 100, CV_8UC3);
    cv::randu(texture, 0, 256);
    cv::GaussianBlur(texture, texture, {5, 5}, 1.2);
    const cv::Mat right = texture(cv::Rect(10, 0, 80, 48)).clone();
    const cv::Mat left = texture(cv::Rect(4, 0, 80, 48)).clone();
    SmallPair p{(dir / "l.png").string(), (dir / "r.png").string(), (dir / "gt.png").string(),
                (dir / "mask.png").string()};
    cv::imwrite(p.left, left);
    cv::imwrite(p.right, right);
    cv::imwrite(p.gt, cv::Mat(48, 80, CV_8UC1, cv::Scalar(24)));
    cv::imwrite(p.mask, cv::Mat(48, 80, CV_8UC1, cv::Scalar(255)));
    return p;
}

TEST(StereoCli, MatchWritesPfmAndPicture) {
    const auto dir = test::freshTempDir();
    const SmallPair p = writeSmallPair(dir);
    for (const char* method : {"paper", "adcensus", "sgbm"}) {
        const auto out = dir / (std::string(method) + ".pfm");
        const auto colour = dir / (std::string(method) + ".png");
        auto r = test::runProgram({icewatchBin(), "match", "--left", p.left, "--right", p.right, "--max-disp", "16",
                                   "--method", method, "--out", out.string(), "--color", colour.string()});
        ASSERT_EQ(r.status, 0) << r.err;
        const cv::Mat d = stereo::readPfm(out);
        EXPECT_EQ(d.size(), cv::Size(80, 48));
        EXPECT_NEAR(d.at<float>(24, 50), 6.0f, 0.5f) << method;
        const cv::Mat picture = cv::imread(colour.string());
        EXPECT_GT(picture.cols, 80) << "the disparity and its colour bar";
        EXPECT_GE(picture.rows, 48);
        EXPECT_EQ(r.out.rfind("disparity 80x48 on [0, 16) px", 0), 0u) << "a one-line summary: " << r.out;
        // The band [3, 16) holds the truth: the same answer there; nothing left of column 3.
        const auto banded = dir / (std::string(method) + "-band.pfm");
        r = test::runProgram({icewatchBin(), "match", "--left", p.left, "--right", p.right, "--min-disp", "3",
                              "--max-disp", "16", "--method", method, "--out", banded.string()});
        ASSERT_EQ(r.status, 0) << r.err;
        const cv::Mat b = stereo::readPfm(banded);
        EXPECT_EQ(b.at<float>(24, 50), d.at<float>(24, 50)) << method;
        EXPECT_EQ(b.at<float>(24, 1), stereo::kInvalidDisparity) << method;
    }
}

TEST(StereoCli, MatchPrintsJsonOnRequest) {
    const auto dir = test::freshTempDir();
    const SmallPair p = writeSmallPair(dir);
    const auto r = test::runProgram({icewatchBin(), "match", "--left", p.left, "--right", p.right, "--min-disp", "2",
                                     "--max-disp", "16", "--method", "sgbm", "--out", (dir / "d.pfm").string(), "--json"});
    ASSERT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j.at("out"), (dir / "d.pfm").string());
    EXPECT_EQ(j.at("min_disp"), 2);
    EXPECT_EQ(j.at("max_disp"), 16);
    EXPECT_EQ(j.at("width"), 80);
    EXPECT_GT(j.at("valid_percent").get<double>(), 50.0);
    EXPECT_LE(j.at("valid_percent").get<double>(), 100.0);
    EXPECT_TRUE(j.at("color").is_null());
}

TEST(StereoCli, EvalPrintsTheMetricsAsJson) {
    const auto dir = test::freshTempDir();
    const SmallPair p = writeSmallPair(dir);
    auto r = test::runProgram({icewatchBin(), "eval", "--left", p.left, "--right", p.right, "--gt", p.gt, "--gt-scale",
                               "4", "--mask", p.mask, "--max-disp", "16", "--noise", "saltpepper:3", "--seed", "9",
                               "--json"});
    ASSERT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j.at("method"), "paper");
    EXPECT_EQ(j.at("noise"), "saltpepper:3");
    EXPECT_GE(j.at("match_ms").get<double>(), 0.0);
    EXPECT_GT(j.at("valid_percent").get<double>(), 99.0);
    // The left 16 columns have no match in the right image; the rest is a clean 6 px shift.
    EXPECT_LT(j.at("bad_percent").get<double>(), 25.0);
    EXPECT_EQ(j.at("min_disp"), 0);
    EXPECT_EQ(j.at("max_disp"), 16);

    r = test::runProgram({icewatchBin(), "eval", "--left", p.left, "--right", p.right, "--gt", p.gt, "--gt-scale", "4",
                          "--mask", p.mask, "--min-disp", "4", "--max-disp", "16", "--json"});
    ASSERT_EQ(r.status, 0) << r.err;
    const auto banded = nlohmann::json::parse(r.out);
    EXPECT_EQ(banded.at("min_disp"), 4);
    EXPECT_LT(banded.at("bad_percent").get<double>(), 25.0);
}

TEST(StereoCli, BenchReportsBothMethodsAndTheRatio) {
    const auto dir = test::freshTempDir();
    const SmallPair p = writeSmallPair(dir);
    auto r = test::runProgram(
        {icewatchBin(), "bench", "--left", p.left, "--right", p.right, "--min-disp", "2", "--max-disp", "16", "--repeat",
         "2", "--json"});
    ASSERT_EQ(r.status, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j.at("min_disp"), 2);
    EXPECT_GT(j.at("paper_ms").get<double>(), 0.0);
    EXPECT_GT(j.at("sgbm_ms").get<double>(), 0.0);
    EXPECT_NEAR(j.at("ratio").get<double>(), j.at("paper_ms").get<double>() / j.at("sgbm_ms").get<double>(), 1e-9);
}

TEST(StereoCli, BadInputGivesAClearErrorAndExitStatus) {
    const auto dir = test::freshTempDir();
    const SmallPair p = writeSmallPair(dir);
    const std::string out = (dir / "d.pfm").string();
    auto match = [&](const std::string& left, const std::string& right, const std::string& maxDisp) {
        return test::runProgram({icewatchBin(), "match", "--left", left, "--right", right, "--max-disp", maxDisp,
                                 "--out", out});
    };
    // Sizes differ.
    const std::string small = (dir / "small.png").string();
    cv::imwrite(small, cv::Mat(20, 30, CV_8UC3, cv::Scalar::all(9)));
    auto r = match(p.left, small, "16");
    EXPECT_EQ(r.status, kExitDataErr);
    EXPECT_NE(r.err.find("sizes differ"), std::string::npos) << r.err;
    // Max disparity out of range.
    r = match(p.left, p.right, "0");
    EXPECT_EQ(r.status, kExitDataErr);
    EXPECT_NE(r.err.find("disparity band [0, 0)"), std::string::npos) << r.err;
    EXPECT_EQ(match(p.left, p.right, "80").status, kExitDataErr);
    EXPECT_EQ(match(p.left, p.right, "-5").status, kExitDataErr);
    // A band too narrow, or below zero.
    auto band = [&](const std::string& minDisp, const std::string& maxDisp) {
        return test::runProgram({icewatchBin(), "match", "--left", p.left, "--right", p.right, "--min-disp", minDisp,
                                 "--max-disp", maxDisp, "--out", out});
    };
    r = band("15", "16");
    EXPECT_EQ(r.status, kExitDataErr);
    EXPECT_NE(r.err.find("disparity band [15, 16): needs at least 3 disparities"), std::string::npos) << r.err;
    r = band("-2", "16");
    EXPECT_EQ(r.status, kExitDataErr);
    EXPECT_NE(r.err.find("must not be negative"), std::string::npos) << r.err;
    EXPECT_EQ(band("x", "16").status, kExitUsage);
    // Missing and unreadable (not an image, empty) files.
    r = match((dir / "missing.png").string(), p.right, "16");
    EXPECT_EQ(r.status, kExitNoInput);
    EXPECT_NE(r.err.find("missing.png"), std::string::npos) << r.err;
    std::ofstream(dir / "garbage.png") << "not a png";
    EXPECT_EQ(match((dir / "garbage.png").string(), p.right, "16").status, kExitNoInput);
    std::ofstream(dir / "empty.png").close();
    EXPECT_EQ(match((dir / "empty.png").string(), p.right, "16").status, kExitNoInput);
    // Wrong types of arguments and values.
    EXPECT_EQ(match(p.left, p.right, "many").status, kExitUsage);
    r = test::runProgram({icewatchBin(), "match", "--left", p.left, "--right", p.right, "--max-disp", "16", "--method",
                          "bm", "--out", out});
    EXPECT_EQ(r.status, kExitUsage);
    r = test::runProgram({icewatchBin(), "eval", "--left", p.left, "--right", p.right, "--gt", p.gt, "--gt-scale", "4",
                          "--max-disp", "16", "--noise", "pink:3"});
    EXPECT_EQ(r.status, kExitDataErr);
    EXPECT_NE(r.err.find("pink:3"), std::string::npos) << r.err;
    // Ground truth of another size.
    r = test::runProgram({icewatchBin(), "eval", "--left", p.left, "--right", p.right, "--gt", small, "--gt-scale", "4",
                          "--max-disp", "16"});
    EXPECT_EQ(r.status, kExitDataErr);
    // An output that cannot be created.
    r = test::runProgram({icewatchBin(), "match", "--left", p.left, "--right", p.right, "--max-disp", "16", "--out",
                          (dir / "no" / "such" / "dir.pfm").string()});
    EXPECT_EQ(r.status, kExitCantCreate);
    // A bad stereo section in --config.
    std::ofstream(dir / "bad.json") << R"({"stereo": {"census_alpha": -1}})";
    r = test::runProgram({icewatchBin(), "match", "--left", p.left, "--right", p.right, "--max-disp", "16", "--out", out,
                          "--config", (dir / "bad.json").string()});
    EXPECT_EQ(r.status, kExitConfig);
    EXPECT_NE(r.err.find("stereo.census_alpha"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace icewatch
