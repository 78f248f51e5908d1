// The icewatch program as a person or a script meets it: exit statuses and messages.
#include <filesystem>
#include <fstream>
#include <iterator>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/common/exit_codes.hpp"
#include "tests/support/run_program.hpp"
#include "tests/support/test_paths.hpp"

namespace icewatch {
namespace {

std::string icewatchBin() { return (test::binDir() / "icewatch").string(); }

TEST(Cli, HelpAndUnknownSubcommand) {
    auto help = test::runProgram({icewatchBin(), "--help"});
    EXPECT_EQ(help.status, 0);
    EXPECT_NE(help.out.find("config"), std::string::npos);
    auto bad = test::runProgram({icewatchBin(), "frobnicate"});
    EXPECT_EQ(bad.status, kExitUsage);
}

// The shipped configuration beside a calibration, as a site would hold them, named relative to it.
std::filesystem::path siteWithCalibration() {
    const auto dir = test::freshTempDir() / "site";
    std::filesystem::create_directories(dir);
    const auto made = test::runProgram({icewatchBin(), "calibrate", "--nominal", "--mode", "640x240", "--out",
                                        (dir / "calibration.yaml").string()});
    EXPECT_EQ(made.status, 0) << made.err;
    std::ifstream shipped(test::sourceDir() / "config/icewatch.json");
    std::string text((std::istreambuf_iterator<char>(shipped)), std::istreambuf_iterator<char>());
    const std::string absolute = "\"/etc/icewatch/calibration.yaml\"";
    text.replace(text.find(absolute), absolute.size(), "\"calibration.yaml\"");
    std::ofstream(dir / "icewatch.json") << text;
    return dir;
}

TEST(Cli, ConfigCheckAcceptsTheShippedFileWithItsCalibration) {
    const auto dir = siteWithCalibration();
    // Run from elsewhere: the calibration is found beside the configuration, not in the working directory.
    auto r = test::runProgram({icewatchBin(), "config", "check", (dir / "icewatch.json").string()});
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("\"valid\":true"), std::string::npos) << r.out;
}

TEST(Cli, ConfigCheckReportsEveryProblemAndTheFilesItNames) {
    const auto dir = siteWithCalibration();
    std::filesystem::remove(dir / "calibration.yaml");
    std::ofstream(dir / "bad.json") << R"({"camera": {"fps": 0, "device": "fake:nowhere"},
        "calibration": {"file": "calibration.yaml"}, "alarm": {"warning_clear": 1e9}})";
    auto r = test::runProgram({icewatchBin(), "config", "check", (dir / "bad.json").string()});
    EXPECT_EQ(r.status, kExitConfig);
    for (const char* problem : {"camera.fps: must be between", "alarm.warning_clear: must be below warning_set",
                                "calibration.file", "calibration.yaml", "camera.device"}) {
        EXPECT_NE(r.err.find(problem), std::string::npos) << problem << " in:\n" << r.err;
    }
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_FALSE(j.at("valid").get<bool>());
    EXPECT_EQ(j.at("problems").size(), 4u) << r.out;
    // A calibration that does not parse is a problem too.
    std::ofstream(dir / "calibration.yaml") << "not: [a calibration";
    std::ofstream(dir / "only.json") << R"({"calibration": {"file": "calibration.yaml"}})";
    r = test::runProgram({icewatchBin(), "config", "check", (dir / "only.json").string()});
    EXPECT_EQ(r.status, kExitConfig);
    EXPECT_NE(r.err.find("calibration.file"), std::string::npos) << r.err;
}

TEST(Cli, HistoryWorksWithoutTheInstalledConfiguration) {
    // The README's example on a laptop: no /etc/icewatch/icewatch.json is no configuration error.
    if (std::filesystem::exists("/etc/icewatch/icewatch.json")) GTEST_SKIP() << "an installed configuration";
    auto r = test::runProgram({icewatchBin(), "history"});
    EXPECT_NE(r.status, kExitConfig) << r.err;
    EXPECT_NE(r.err.find("history.sqlite"), std::string::npos) << r.err;
    // A configuration named on the command line must exist.
    r = test::runProgram({icewatchBin(), "history", "--config", "/nonexistent/icewatch.json"});
    EXPECT_EQ(r.status, kExitConfig) << r.err;
}

TEST(Cli, ConfigCheckExits78NamingTheKey) {
    const auto dir = test::freshTempDir();
    std::ofstream(dir / "bad.json") << R"({"camera": {"fps": 0}})";
    auto r = test::runProgram({icewatchBin(), "config", "check", (dir / "bad.json").string()});
    EXPECT_EQ(r.status, kExitConfig);
    EXPECT_NE(r.err.find("bad.json: camera.fps: must be between"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace icewatch
