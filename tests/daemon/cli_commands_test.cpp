// icewatch history / status / baseline capture against a state directory and a live API.
#include <fstream>

#include <gtest/gtest.h>

#include "daemon/baseline_store.hpp"
#include "daemon/http_api.hpp"
#include "tests/daemon/rig.hpp"
#include "tests/support/run_program.hpp"

namespace icewatch::daemon::test {
namespace {

std::string icewatchBin() { return (icewatch::test::binDir() / "icewatch").string(); }

TEST(CliCommands, HistoryAsJsonLinesAndCsv) {
    Rig rig;
    rig.daemon->runUntil(rig.at(2 * 600 + 1));
    const std::string stateDir = rig.dir.string();
    auto jsonl = icewatch::test::runProgram({icewatchBin(), "history", "--state-dir", stateDir, "--since",
                                             "2026-01-01T00:10:00Z", "--format", "jsonl"});
    ASSERT_EQ(jsonl.status, 0) << jsonl.err;
    std::istringstream lines(jsonl.out);
    std::vector<nlohmann::json> rows;
    for (std::string line; std::getline(lines, line);) rows.push_back(nlohmann::json::parse(line));
    ASSERT_EQ(rows.size(), 2u);
    EXPECT_EQ(rows[0]["time"], "2026-01-01T00:10:00Z");
    EXPECT_EQ(rows[1]["volume_mm3"], 1000.0);

    auto csv = icewatch::test::runProgram(
        {icewatchBin(), "history", "--state-dir", stateDir, "--since", "2026-01-01", "--format", "csv"});
    ASSERT_EQ(csv.status, 0) << csv.err;
    EXPECT_EQ(csv.out.substr(0, csv.out.find('\n')), historyCsvHeader());
    EXPECT_EQ(std::count(csv.out.begin(), csv.out.end(), '\n'), 4);
    EXPECT_NE(csv.out.find("2026-01-01T00:20:00Z,ok,,1000.0,50.0,1.0,0.05,3.0,1000.0,100.0,90.0,alarm,ok,,test-version,cafe"), std::string::npos)
        << csv.out;

    auto bad = icewatch::test::runProgram({icewatchBin(), "history", "--state-dir", stateDir, "--since", "soon"});
    EXPECT_EQ(bad.status, 64);
    auto missing = icewatch::test::runProgram({icewatchBin(), "history", "--state-dir", (rig.dir / "nope").string()});
    EXPECT_EQ(missing.status, 66) << missing.err;
}

TEST(CliCommands, StatusPrintsTheLatestResult) {
    Rig rig;
    HttpApi http(*rig.daemon, rig.config.http);
    const std::string url = "http://127.0.0.1:" + std::to_string(http.port());
    auto early = icewatch::test::runProgram({icewatchBin(), "status", "--url", url});
    EXPECT_EQ(early.status, 75) << early.err;
    rig.daemon->runOnce();
    auto r = icewatch::test::runProgram({icewatchBin(), "status", "--url", url});
    ASSERT_EQ(r.status, 0) << r.err;
    const auto doc = nlohmann::json::parse(r.out);
    EXPECT_EQ(doc["status"], "ok");
    EXPECT_EQ(doc["stale"], false);
}

TEST(CliCommands, StatusWithoutADaemonIsUnavailable) {
    auto r = icewatch::test::runProgram({icewatchBin(), "status", "--url", "http://127.0.0.1:1"});
    EXPECT_EQ(r.status, 69);
    EXPECT_NE(r.err.find("is icewatchd running?"), std::string::npos) << r.err;
}

TEST(CliCommands, BaselineCaptureRefusesAStateDirInUse) {
    Rig rig;
    const auto config = rig.dir / "config.json";
    std::ofstream(config) << "{}";
    auto r = icewatch::test::runProgram(
        {icewatchBin(), "baseline", "capture", "--config", config.string(), "--state-dir", rig.dir.string()});
    EXPECT_EQ(r.status, 75);
    EXPECT_NE(r.err.find("in use by another icewatchd"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace icewatch::daemon::test

namespace icewatch::daemon::test {
namespace {

TEST(CliCommands, BaselineCaptureWhileTheLastResultShowsIceNeedsForce) {
    const auto dir = icewatch::test::freshTempDir();
    {
        Rig rig({}, dir);
        rig.daemon->runOnce();  // 1000 mm³: alarm
    }
    const auto config = dir / "icewatch.json";
    std::ofstream(config) << R"({"gpio": {"chip": "fake"}})";
    auto r = icewatch::test::runProgram(
        {icewatchBin(), "baseline", "capture", "--config", config.string(), "--state-dir", dir.string()});
    EXPECT_EQ(r.status, 65) << r.err;
    EXPECT_NE(r.err.find("the last result shows ice (alarm level alarm)"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("--force"), std::string::npos) << r.err;
}

TEST(CliCommands, BaselineRestoreSwapsInThePreviousOne) {
    const auto dir = icewatch::test::freshTempDir();
    const StereoPair pair = texturedPair(0.5);
    std::string error;
    ASSERT_TRUE(saveBaseline(dir, {testEpoch(), "c0ffee", pair, "first", {}}, error)) << error;
    const auto config = dir / "icewatch.json";
    std::ofstream(config) << "{}";
    const std::vector<std::string> restore{icewatchBin(), "baseline", "restore", "--config", config.string(),
                                           "--state-dir", dir.string()};
    auto r = icewatch::test::runProgram(restore);
    EXPECT_EQ(r.status, 66) << "nothing to go back to: " << r.err;
    ASSERT_TRUE(saveBaseline(dir, {testEpoch() + std::chrono::hours(1), "c0ffee", pair, "second", {}}, error)) << error;
    r = icewatch::test::runProgram(restore);
    EXPECT_EQ(r.status, 0) << r.err;
    const auto record = loadBaseline(dir, error);
    ASSERT_TRUE(record) << error;
    EXPECT_EQ(record->requestedBy, "first");
}

TEST(CliCommands, ConfigCheckOfANumberNoDoubleHoldsExits78) {
    auto r = icewatch::test::runProgram(
        {icewatchBin(), "config", "check",
         (icewatch::test::sourceDir() / "tests/core/config/bad-inputs/overflow.json").string()});
    EXPECT_EQ(r.status, 78) << r.err;
    EXPECT_NE(r.err.find("daemon.interval_s"), std::string::npos) << r.err;
    const auto dir = icewatch::test::freshTempDir();
    std::ofstream(dir / "open.json") << R"({"http": {"address": "0.0.0.0", "token": ""}})";
    r = icewatch::test::runProgram({icewatchBin(), "config", "check", (dir / "open.json").string()});
    EXPECT_EQ(r.status, 78) << r.err;
}

}  // namespace
}  // namespace icewatch::daemon::test
