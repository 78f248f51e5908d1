#include "daemon/daemon.hpp"

#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "core/common/error.hpp"
#include "daemon/baseline_store.hpp"
#include "daemon/notifier.hpp"
#include "tests/daemon/rig.hpp"

namespace icewatch::daemon::test {
namespace {

using gpio::LineTransition;

TEST(Daemon, LatestJsonCarriesEveryField) {
    Rig rig({}, icewatch::test::freshTempDir(), [](ScriptedChain& c) {
        c.script = [](int call, const StereoPair&) { return okResult(1000.0 * call, 10.0, 2.0 * call); };
    });
    ASSERT_TRUE(rig.daemon->runOnce());
    const nlohmann::json doc = rig.latestFile();
    ASSERT_TRUE(doc.is_object());
    EXPECT_EQ(doc["schema"], 1);
    EXPECT_EQ(doc["time"], "2026-01-01T00:00:00Z");
    EXPECT_EQ(doc["status"], "ok");
    EXPECT_TRUE(doc["reason"].is_null());
    EXPECT_DOUBLE_EQ(doc["volume_mm3"].get<double>(), 1000.0);  // the burst's average, measured once
    EXPECT_DOUBLE_EQ(doc["uncertainty_mm3"].get<double>(), 10.0);
    EXPECT_EQ(rig.chain->calls, 1);
    EXPECT_DOUBLE_EQ(doc["mean_thickness_mm"].get<double>(), 2.0);
    EXPECT_DOUBLE_EQ(doc["max_thickness_mm"].get<double>(), 6.0);
    EXPECT_DOUBLE_EQ(doc["ice_area_mm2"].get<double>(), 500.0);
    EXPECT_DOUBLE_EQ(doc["beyond_outline_mm3"].get<double>(), 100.0);
    EXPECT_DOUBLE_EQ(doc["valid_percent"].get<double>(), 90.0);
    EXPECT_EQ(doc["alarm"], "alarm");
    EXPECT_EQ(doc["camera"], "ok");
    EXPECT_EQ(doc["quality"]["frames_grabbed"], 3);
    EXPECT_EQ(doc["quality"]["frames_healthy"], 3);
    EXPECT_EQ(doc["quality"]["frames_measured"], 3);
    EXPECT_TRUE(doc["quality"]["flags"].empty());
    for (const char* stage : {"grab", "average", "measure", "total", "chain_match", "chain_integrate"}) {
        EXPECT_TRUE(doc["timings_ms"].contains(stage)) << stage;
    }
    EXPECT_EQ(doc["version"], "test-version");
    EXPECT_EQ(doc["config_sha256"], "cafe");
    EXPECT_FALSE(doc.contains("stale")) << "staleness is computed when served, not stored";
    for (const char* picture : {"left", "disparity", "thickness"}) {
        EXPECT_TRUE(std::filesystem::exists(rig.dir / "images" / (std::string(picture) + ".png"))) << picture;
    }
}

// What the service manager was told, with its watchdog on (WatchdogSec=120).
class RecordingNotifier : public Notifier {
public:
    void notify(const std::string& message) override { messages.push_back(message); }
    std::optional<std::chrono::microseconds> watchdogInterval() const override { return std::chrono::seconds(120); }
    long count(const std::string& message) const { return std::count(messages.begin(), messages.end(), message); }
    std::vector<std::string> messages;
};

// A long chain shows that it is working: the stored baseline measured at start extends the start
// timeout stage by stage, and once the loop runs each of the chain's stages pings the watchdog, so
// a slow box is not killed in the middle of a measurement (a stage that hangs still stops the pings).
TEST(Daemon, TheChainsStagesKeepTheServiceManagerInformed) {
    const auto dir = icewatch::test::freshTempDir();
    const config::Config config = testConfig(dir);
    prepareStateDir(dir);
    std::string error;
    ASSERT_TRUE(saveBaseline(dir, {testEpoch(), "c0ffee", texturedPair(), "test", {}}, error)) << error;
    auto chain = std::make_unique<ScriptedChain>();
    chain->baselineSet = false;
    chain->stages = 40;
    const ScriptedChain* scripted = chain.get();
    auto gpioLog = std::make_shared<gpio::TransitionLog>();
    ManualClock clock(testEpoch());
    RecordingNotifier notifier;
    Daemon daemon(config, DaemonOptions{{}, "cafe", "test-version"}, clock,
                  DaemonParts{std::make_unique<ScriptedSource>(), std::move(chain),
                              gpio::openScadaOutputs(config.gpio, gpioLog)},
                  &notifier);
    EXPECT_TRUE(scripted->baselineSet) << "the stored baseline is measured at start";
    EXPECT_EQ(notifier.messages, std::vector<std::string>(40, "EXTEND_TIMEOUT_USEC=120000000"));

    notifier.messages.clear();
    daemon.runUntil(testEpoch() + std::chrono::seconds(1));
    ASSERT_FALSE(notifier.messages.empty());
    EXPECT_EQ(notifier.messages.front().rfind("READY=1", 0), 0u) << notifier.messages.front();
    EXPECT_EQ(scripted->calls, 1);
    EXPECT_GE(notifier.count("WATCHDOG=1"), 40) << "each of the chain's stages";
    EXPECT_EQ(notifier.count("EXTEND_TIMEOUT_USEC=120000000"), 0) << "running: the watchdog's turn";
}

TEST(Daemon, StaleOnceOlderThanTwoIntervals) {
    Rig rig;
    ASSERT_TRUE(rig.daemon->runOnce());
    EXPECT_FALSE((*rig.daemon->latest())["stale"].get<bool>());
    rig.clock.advance(std::chrono::seconds(1200));
    EXPECT_FALSE((*rig.daemon->latest())["stale"].get<bool>());
    rig.clock.advance(std::chrono::seconds(1));
    EXPECT_TRUE((*rig.daemon->latest())["stale"].get<bool>());
    EXPECT_EQ(rig.daemon->health()["status"], "fault");
}

TEST(Daemon, ADayOfTenMinuteCyclesInHistory) {
    Rig rig({}, icewatch::test::freshTempDir(), [](ScriptedChain& c) {
        c.script = [](int, const StereoPair&) { return okResult(50.0); };
    });
    rig.daemon->runUntil(rig.at(24 * 3600));
    const auto rows = rig.daemon->history(testEpoch(), 100000);
    ASSERT_EQ(rows.size(), 144u);
    EXPECT_EQ(rows.front()["time"], "2026-01-01T00:00:00Z");
    EXPECT_EQ(rows[1]["time"], "2026-01-01T00:10:00Z");
    EXPECT_EQ(rows.back()["time"], "2026-01-01T23:50:00Z");
    EXPECT_EQ(rig.chain->calls, 144) << "one averaged capture measured per cycle";
    for (const auto& row : rows) {
        EXPECT_EQ(row["status"], "ok");
        EXPECT_EQ(row["alarm"], "none");
        EXPECT_DOUBLE_EQ(row["volume_mm3"].get<double>(), 50.0);
        EXPECT_EQ(row["quality"]["frames_measured"], 3);
    }
    // Nothing moved all day: one transition per line when the first result came.
    EXPECT_EQ(rig.transitions(), (std::vector<LineTransition>{{"alarm", true}, {"healthy", true}}));
    EXPECT_EQ(rig.latestFile()["time"], "2026-01-01T23:50:00Z");
}

TEST(Daemon, HistoryIsPrunedByAge) {
    Rig rig(
        [](config::Config& c) {
            c.history.retentionDays = 1;
            c.daemon.intervalS = 3600;
        },
        icewatch::test::freshTempDir(),
        [](ScriptedChain& c) { c.script = [](int, const StereoPair&) { return okResult(50.0); }; });
    rig.daemon->runUntil(rig.at(2 * 24 * 3600));
    const auto rows = rig.daemon->history(testEpoch(), 100000);
    // The last cycle ran at 47:00; rows from 23:00 on are within a day of it.
    ASSERT_EQ(rows.size(), 25u);
    EXPECT_EQ(rows.front()["time"], "2026-01-01T23:00:00Z");
}

TEST(Daemon, GpioFollowsAnIceSeriesWithHysteresis) {
    const std::vector<double> series{0, 90, 120, 180, 250, 300, 170, 140, 90, 70, 0};
    const std::vector<std::string> levels{"none",  "none",  "warning", "warning", "alarm", "alarm",
                                          "alarm", "warning", "warning", "none",  "none"};
    Rig rig({}, icewatch::test::freshTempDir(), [&](ScriptedChain& c) {
        c.script = [&](int call, const StereoPair&) { return okResult(series[static_cast<std::size_t>(call - 1)]); };
    });
    auto closed = std::make_shared<bool>(false);
    rig.source->closedOutside = closed;
    rig.daemon->runUntil(rig.at(600 * static_cast<int>(series.size() - 1) + 1));
    const auto rows = rig.daemon->history(testEpoch(), 1000);
    ASSERT_EQ(rows.size(), series.size());
    for (std::size_t i = 0; i < rows.size(); ++i) {
        EXPECT_EQ(rows[i]["alarm"], levels[i]) << "cycle " << i << " volume " << series[i];
    }
    rig.daemon.reset();  // shutdown: outputs left fail-safe
    const std::vector<LineTransition> expected{
        {"alarm", true},   {"healthy", true},  // first result: no ice, system healthy
        {"alarm", false},                      // 250: alarm (the warning at 120 is not wired out)
        {"alarm", true},                       // 140: back to warning, below alarm_clear 150
        {"healthy", false}, {"alarm", false},  // shutdown
    };
    EXPECT_EQ(rig.transitions(), expected);
    EXPECT_TRUE(*closed) << "the camera is released on shutdown";
}

TEST(Daemon, AnAlarmJudgedOnTheUpperBoundCountsWhatTheReadingCannotRuleOut) {
    // 120 ± 90: a warning on the estimate, an alarm on what may be there (alarm_set 200).
    for (const std::string judge : {"estimate", "upper_bound"}) {
        Rig rig([&](config::Config& c) { c.alarm.judge = judge; }, icewatch::test::freshTempDir(),
                [](ScriptedChain& c) { c.script = [](int, const StereoPair&) { return okResult(120.0, 90.0, 2.0); }; });
        rig.daemon->runUntil(rig.at(1));
        const nlohmann::json doc = rig.latestFile();
        EXPECT_EQ(doc["alarm"], judge == "estimate" ? "warning" : "alarm") << judge;
        EXPECT_EQ(doc["volume_mm3"], 120.0);
        EXPECT_EQ(doc["uncertainty_mm3"], 90.0);
        EXPECT_EQ(doc["mean_thickness_uncertainty_mm"], 1.5);
    }
}

TEST(Daemon, CameraUnpluggedMidCycleThenPluggedBack) {
    Rig rig({}, icewatch::test::freshTempDir(), [](ScriptedChain& c) {
        c.script = [](int, const StereoPair&) { return okResult(50.0); };
    });
    rig.source->unplugAtGrab = 5;  // the second frame of the second cycle's burst
    rig.daemon->runUntil(rig.at(900));
    nlohmann::json doc = rig.latestFile();
    EXPECT_EQ(doc["time"], "2026-01-01T00:10:00Z");
    EXPECT_EQ(doc["status"], "fault");
    EXPECT_EQ(doc["alarm"], "fault");
    EXPECT_EQ(doc["camera"], "offline");
    EXPECT_TRUE(doc["volume_mm3"].is_null());
    EXPECT_NE(doc["reason"].get<std::string>().find("camera lost at frame 2 of the burst"), std::string::npos)
        << doc["reason"];
    EXPECT_EQ(rig.daemon->health()["camera"], "offline");

    rig.source->plugged = true;  // plugged back at 00:15:00
    rig.daemon->runUntil(rig.at(1000));
    doc = rig.latestFile();
    // Measured as soon as the camera check saw it, not at the next scheduled cycle (00:20).
    EXPECT_EQ(doc["time"], "2026-01-01T00:15:00Z");
    EXPECT_EQ(doc["status"], "ok");
    EXPECT_EQ(doc["alarm"], "none");
    EXPECT_EQ(doc["camera"], "ok");
    const auto rows = rig.daemon->history(testEpoch(), 1000);
    ASSERT_EQ(rows.size(), 3u);
    EXPECT_EQ(rows[1]["status"], "fault");
    EXPECT_EQ(rig.transitions(), (std::vector<LineTransition>{{"alarm", true},
                                                               {"healthy", true},
                                                               {"healthy", false},
                                                               {"alarm", false},
                                                               {"alarm", true},
                                                               {"healthy", true}}));
}

TEST(Daemon, CameraVanishingBetweenCyclesIsAFaultWithinACheck) {
    Rig rig({}, icewatch::test::freshTempDir(), [](ScriptedChain& c) {
        c.script = [](int, const StereoPair&) { return okResult(50.0); };
    });
    rig.daemon->runUntil(rig.at(100));
    rig.source->plugged = false;
    rig.daemon->runUntil(rig.at(106));
    const nlohmann::json doc = rig.latestFile();
    EXPECT_EQ(doc["status"], "fault");
    EXPECT_EQ(doc["time"], "2026-01-01T00:01:40Z");  // the first check after it went
    EXPECT_EQ(doc["reason"], "camera offline: no such device");
    EXPECT_EQ(rig.transitions().back(), (LineTransition{"alarm", false}));
    EXPECT_EQ(rig.daemon->history(testEpoch(), 100).size(), 1u) << "between-cycle faults are not cycles";
}

TEST(Daemon, RefusedResultsDoNotMoveTheAlarm) {
    Rig rig({}, icewatch::test::freshTempDir(), [](ScriptedChain& c) {
        c.script = [](int call, const StereoPair&) {
            return call <= 1 ? okResult(120.0) : refusedResult("12 % valid disparities in the region, 40 % needed");
        };
    });
    rig.daemon->runUntil(rig.at(601));
    nlohmann::json doc = rig.latestFile();
    EXPECT_EQ(doc["status"], "refused");
    EXPECT_EQ(doc["alarm"], "warning");
    EXPECT_EQ(doc["reason"], "12 % valid disparities in the region, 40 % needed");
    EXPECT_TRUE(doc["quality"]["flags"].empty());
    EXPECT_EQ(doc["quality"]["frames_measured"], 3);

    rig.source->frame = [](int) { return texturedPair(0.1); };  // night
    rig.daemon->runUntil(rig.at(1201));
    doc = rig.latestFile();
    EXPECT_EQ(doc["status"], "refused");
    EXPECT_EQ(doc["alarm"], "warning");
    EXPECT_EQ(doc["camera"], "degraded");
    EXPECT_EQ(doc["quality"]["frames_healthy"], 0);
    EXPECT_NE(doc["reason"].get<std::string>().find("the burst gave no capture: 0 usable frames of 3 (2 needed)"),
              std::string::npos)
        << doc["reason"];
    EXPECT_EQ(doc["quality"]["flags"].size(), 3u);
    EXPECT_EQ(doc["quality"]["flags"][0]["flag"], "dark");
    EXPECT_NE(doc["quality"]["flags"][0]["reason"].get<std::string>().find("frame 1: left eye: mean level"),
              std::string::npos);
    EXPECT_EQ(rig.transitions(), (std::vector<LineTransition>{{"alarm", true}, {"healthy", true}}));
}

TEST(Daemon, OneBadFrameIsDroppedAndTheRestMeasured) {
    Rig rig({}, icewatch::test::freshTempDir(), [](ScriptedChain& c) {
        c.script = [](int, const StereoPair&) { return okResult(50.0); };
    });
    rig.source->frame = [](int grab) { return grab == 2 ? texturedPair(0.1) : texturedPair(); };
    ASSERT_TRUE(rig.daemon->runOnce());
    const nlohmann::json doc = rig.latestFile();
    EXPECT_EQ(doc["status"], "ok");
    EXPECT_EQ(doc["camera"], "degraded");
    EXPECT_EQ(doc["quality"]["frames_healthy"], 2);
    EXPECT_EQ(doc["quality"]["frames_measured"], 2);
    EXPECT_EQ(doc["quality"]["flags"][0]["flag"], "dark");
    EXPECT_EQ(rig.chain->calls, 1) << "the two good frames are averaged and measured once";
}

TEST(Daemon, MeasurementFailureIsAFault) {
    Rig rig({}, icewatch::test::freshTempDir(), [](ScriptedChain& c) {
        c.script = [](int, const StereoPair&) {
            ChainResult r;
            r.status = ChainResult::Status::Failed;
            r.reason = "rectification maps do not fit the frame";
            return r;
        };
    });
    const auto result = rig.daemon->runOnce();
    ASSERT_TRUE(result);
    EXPECT_EQ(result->status, CycleStatus::Fault);
    EXPECT_EQ(rig.latestFile()["reason"], "measurement failed: rectification maps do not fit the frame");
    EXPECT_EQ(rig.latestFile()["alarm"], "fault");
    EXPECT_TRUE(rig.transitions().empty()) << "never shown as no ice";
}

TEST(Daemon, NoBaselineUntilOneIsCapturedThenItSurvivesARestart) {
    const auto dir = icewatch::test::freshTempDir();
    {
        Rig rig({}, dir, [](ScriptedChain& c) {
            c.baselineSet = false;
            c.script = [](int, const StereoPair&) { return okResult(50.0); };
        });
        const auto first = rig.daemon->runOnce();
        ASSERT_TRUE(first);
        EXPECT_EQ(first->status, CycleStatus::NoBaseline);
        EXPECT_EQ(rig.latestFile()["status"], "no_baseline");
        EXPECT_EQ(rig.latestFile()["alarm"], "fault");
        EXPECT_TRUE(rig.daemon->health()["baseline"].is_null());

        rig.daemon->requestBaseline();
        rig.daemon->runUntil(rig.at(1));
        EXPECT_EQ(rig.latestFile()["status"], "ok") << "a cycle follows a new baseline at once";
        const nlohmann::json stored = readJsonFile(dir / "baseline" / "baseline.json");
        EXPECT_EQ(stored["calibration_sha256"], "c0ffee");
        EXPECT_EQ(stored["time"], "2026-01-01T00:00:00Z");
        EXPECT_EQ(rig.daemon->health()["baseline"]["time"], "2026-01-01T00:00:00Z");
        EXPECT_TRUE(rig.daemon->health()["last_baseline_capture"]["ok"].get<bool>());
    }
    {
        Rig again({}, dir, [](ScriptedChain& c) { c.baselineSet = false; });
        EXPECT_TRUE(again.chain->hasBaseline()) << "the stored baseline is loaded at start";
        EXPECT_FALSE(again.chain->baselineNoise.left.empty()) << "with the noise draw its burst gave";
        EXPECT_EQ(again.chain->baselineNoise.left.size(), again.chain->baselineNoise.right.size());
        EXPECT_EQ(again.daemon->runOnce()->status, CycleStatus::Ok);
    }
    {
        Rig recalibrated({}, dir, [](ScriptedChain& c) {
            c.baselineSet = false;
            c.calibration = "another-calibration";
        });
        EXPECT_EQ(recalibrated.daemon->runOnce()->status, CycleStatus::NoBaseline);
    }
}

TEST(Daemon, BaselineCaptureRefusesADarkScene) {
    Rig rig({}, icewatch::test::freshTempDir(), [](ScriptedChain& c) { c.baselineSet = false; });
    rig.source->frame = [](int) { return texturedPair(0.1); };
    rig.daemon->requestBaseline();
    rig.daemon->runUntil(rig.at(1));
    const auto capture = rig.daemon->health()["last_baseline_capture"];
    EXPECT_FALSE(capture["ok"].get<bool>());
    EXPECT_NE(capture["reason"].get<std::string>().find("the burst gave no clean capture: 0 usable frames"),
              std::string::npos)
        << capture["reason"];
    EXPECT_FALSE(std::filesystem::exists(rig.dir / "baseline" / "baseline.json"));
}

TEST(Daemon, LatchedAlarmNeedsAReset) {
    Rig rig([](config::Config& c) { c.alarm.latch = true; }, icewatch::test::freshTempDir(), [](ScriptedChain& c) {
        c.script = [](int call, const StereoPair&) { return okResult(call <= 1 ? 250.0 : 10.0); };
    });
    rig.daemon->runUntil(rig.at(601));
    EXPECT_EQ(rig.latestFile()["alarm"], "alarm");
    rig.daemon->requestAlarmReset();
    rig.daemon->runUntil(rig.at(602));
    EXPECT_EQ(rig.latestFile()["alarm"], "none");
    EXPECT_EQ(rig.transitions().back(), (LineTransition{"alarm", true}));
}

TEST(Daemon, ReloadKeepsTheOldConfigWhenTheNewOneIsInvalid) {
    const auto dir = icewatch::test::freshTempDir();
    const auto file = dir / "icewatch.json";
    std::ofstream(file) << R"({"daemon": {"interval_s": 600}})";
    Rig rig({}, dir / "state");
    // Re-create the daemon with the config file known, keeping the rig's doubles simple.
    rig.daemon.reset();
    auto source = std::make_unique<ScriptedSource>();
    auto chain = std::make_unique<ScriptedChain>();
    chain->script = [](int, const StereoPair&) { return okResult(50.0); };
    Daemon daemon(rig.config, DaemonOptions{file, "first", "v"}, rig.clock,
                  DaemonParts{std::move(source), std::move(chain), nullptr});

    std::ofstream(file) << R"({"daemon": {"interval_s": "often"}})";
    daemon.requestReload();
    daemon.runUntil(rig.at(1));
    nlohmann::json health = daemon.health();
    EXPECT_EQ(health["reloads"]["failed"], 1);
    EXPECT_NE(health["reloads"]["last_error"].get<std::string>().find("daemon.interval_s: must be an integer"),
              std::string::npos);
    EXPECT_EQ(health["interval_s"], 600);
    EXPECT_EQ(health["config_sha256"], "first");

    // nlohmann::json throws out_of_range for it, which escaped the reload as "internal error".
    std::ofstream(file) << R"({"daemon": {"interval_s": 1e999}})";
    daemon.requestReload();
    daemon.runUntil(rig.at(1));
    health = daemon.health();
    EXPECT_EQ(health["reloads"]["failed"], 2);
    EXPECT_NE(health["reloads"]["last_error"].get<std::string>().find("daemon.interval_s: the number 1e999 does not fit"),
              std::string::npos)
        << health["reloads"]["last_error"];
    EXPECT_EQ(health["interval_s"], 600);

    std::ofstream(file) << R"({"daemon": {"interval_s": 300}})";
    daemon.requestReload();
    daemon.runUntil(rig.at(2));
    health = daemon.health();
    EXPECT_EQ(health["reloads"]["count"], 3);
    EXPECT_TRUE(health["reloads"]["last_error"].is_null());
    EXPECT_EQ(health["interval_s"], 300);
    EXPECT_EQ(health["config_sha256"].get<std::string>().size(), 64u);
    // The state directory is not taken from the reloaded file (a restart-only setting).
    EXPECT_EQ(health["state_dir"], (dir / "state").string());
}

TEST(Daemon, TheReplacedBaselineIsKeptAndCanBeRestored) {
    Rig rig({}, icewatch::test::freshTempDir(), [](ScriptedChain& c) { c.baselineSet = false; });
    rig.daemon->requestBaseline("first");
    rig.daemon->runUntil(rig.at(1));
    rig.daemon->runUntil(rig.at(100));
    rig.daemon->requestBaseline("second");
    rig.daemon->runUntil(rig.at(101));
    const auto baseline = rig.dir / "baseline";
    EXPECT_EQ(readJsonFile(baseline / "baseline.json")["requested_by"], "second");
    EXPECT_EQ(readJsonFile(baseline / "baseline.previous.json")["requested_by"], "first");
    EXPECT_EQ(rig.daemon->health()["baseline"]["time"], "2026-01-01T00:01:40Z");

    rig.daemon->requestBaselineRestore("test");
    rig.daemon->runUntil(rig.at(102));
    EXPECT_EQ(readJsonFile(baseline / "baseline.json")["requested_by"], "first");
    EXPECT_EQ(readJsonFile(baseline / "baseline.previous.json")["requested_by"], "second");
    EXPECT_EQ(rig.daemon->health()["baseline"]["time"], "2026-01-01T00:00:00Z") << "the restored one is in use";
    // Both records' images are still there: restoring again goes back.
    std::string error;
    ASSERT_TRUE(restoreBaseline(rig.dir, error)) << error;
    EXPECT_TRUE(loadBaseline(rig.dir, error)) << error;
}

TEST(Daemon, ALatestJsonOfTheWrongShapeIsTreatedAsAbsent) {
    for (const char* text : {R"({"time": "2026-01-01T00:00:00Z", "status": "ok"})", R"({"alarm": 5})", "[1, 2]",
                             R"({"time": 1, "status": "ok", "alarm": "none", "camera": "ok"})"}) {
        const auto dir = icewatch::test::freshTempDir();
        std::ofstream(dir / "latest.json") << text;
        Rig rig({}, dir);
        EXPECT_FALSE(rig.daemon->latest()) << text;
        const auto health = rig.daemon->health();  // read a missing key of a const json: undefined behaviour
        EXPECT_EQ(health["alarm"], "fault") << text;
        EXPECT_EQ(rig.daemon->alarmLevel(), alarm::AlarmLevel::Fault) << text;
    }
}

TEST(Daemon, ADamagedHistoryIsMovedAsideAndMeasuringGoesOn) {
    const auto dir = icewatch::test::freshTempDir();
    std::ofstream(dir / "history.sqlite") << std::string(8192, 'x');  // not a database
    Rig rig({}, dir);
    ASSERT_TRUE(rig.daemon->runOnce());
    EXPECT_EQ(rig.daemon->history(testEpoch(), 10).size(), 1u) << "a new history took the row";
    bool movedAside = false;
    for (const auto& entry : std::filesystem::directory_iterator(dir)) {
        if (entry.path().filename().string().rfind("history.sqlite.damaged-", 0) == 0) {
            movedAside = true;
            EXPECT_EQ(std::filesystem::file_size(entry.path()), 8192u) << "kept as it was, for a person";
        }
    }
    EXPECT_TRUE(movedAside);
    const auto health = rig.daemon->health();
    EXPECT_NE(health["history_recovery"].get<std::string>().find("was damaged"), std::string::npos) << health;
    EXPECT_EQ(health["status"], "degraded");
}

TEST(Daemon, AFailedWriteOfLatestJsonIsAFaultUntilAWriteSucceeds) {
    Rig rig;
    // rename() cannot replace a non-empty directory: the write of latest.json fails like on a full disk.
    std::filesystem::create_directories(rig.dir / "latest.json" / "blocked");
    ASSERT_TRUE(rig.daemon->runOnce());
    auto health = rig.daemon->health();
    EXPECT_EQ(health["status"], "fault");
    EXPECT_NE(health["storage_fault"].get<std::string>().find("latest.json"), std::string::npos) << health;
    EXPECT_NE((*rig.daemon->latest())["storage_fault"].get<std::string>().find("cannot write"), std::string::npos);

    std::filesystem::remove_all(rig.dir / "latest.json");
    rig.daemon->requestMeasure();
    rig.daemon->runUntil(rig.at(1));
    health = rig.daemon->health();
    EXPECT_EQ(health["status"], "ok") << health;
    EXPECT_TRUE(health["storage_fault"].is_null());
    EXPECT_TRUE(rig.latestFile()["storage_fault"].is_null());
}

TEST(Daemon, OneDaemonPerStateDirectory) {
    const auto dir = icewatch::test::freshTempDir();
    Rig first({}, dir);
    try {
        Rig second({}, dir);
        FAIL() << "a second daemon on the same state directory must not start";
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), kExitTempFail);
    }
}


namespace never_silent {

// The line states SCADA reads after a series of transitions (both start de-energised).
std::pair<bool, bool> alarmAndHealthy(const std::vector<LineTransition>& transitions) {
    bool alarm = false, healthy = false;
    for (const auto& t : transitions) (t.line == "alarm" ? alarm : healthy) = t.energised;
    return {alarm, healthy};
}

// Publications as the SCADA interfaces receive them.
struct RecordingSink : scada::PublicationSink {
    void published(const scada::Publication& p) override { seen.push_back(p); }
    std::vector<scada::Publication> seen;
};

std::vector<std::string> alarmsOf(const std::vector<nlohmann::json>& rows) {
    std::vector<std::string> alarms;
    for (const auto& row : rows) alarms.push_back(row["alarm"]);
    return alarms;
}

TEST(Daemon, CleanThenIcedButRefusedLongerThanMaxRefusedIsAFault) {
    // One clean reading, then the ice grows and every cycle is refused.
    Rig rig({}, icewatch::test::freshTempDir(), [](ScriptedChain& c) {
        c.script = [](int call, const StereoPair&) {
            return call == 1 ? okResult(0.0) : refusedResult("the motion between the captures is not observable");
        };
    });
    rig.daemon->runUntil(rig.at(1201));
    EXPECT_EQ(alarmsOf(rig.daemon->history(testEpoch(), 100)), (std::vector<std::string>{"none", "none", "none"}))
        << "within max_refused_s (three intervals) a refusal keeps the level";
    EXPECT_EQ(alarmAndHealthy(rig.transitions()), std::make_pair(true, true));
    EXPECT_FALSE((*rig.daemon->latest())["stale"].get<bool>());

    rig.daemon->runUntil(rig.at(1801));
    EXPECT_EQ(alarmsOf(rig.daemon->history(testEpoch(), 100)),
              (std::vector<std::string>{"none", "none", "none", "fault"}));
    const nlohmann::json doc = rig.latestFile();
    EXPECT_EQ(doc["status"], "refused");
    EXPECT_EQ(doc["alarm"], "fault");
    EXPECT_EQ(doc["last_ok"], "2026-01-01T00:00:00Z");
    EXPECT_NE(doc["alarm_reason"].get<std::string>().find("no ok result since 2026-01-01T00:00:00Z"),
              std::string::npos)
        << doc["alarm_reason"];
    EXPECT_EQ(alarmAndHealthy(rig.transitions()), std::make_pair(false, false)) << "both lines drop, as for a fault";
    const nlohmann::json served = *rig.daemon->latest();
    EXPECT_TRUE(served["stale"].get<bool>());
    EXPECT_EQ(served["stale_since"], "2026-01-01T00:30:00Z");
    const nlohmann::json health = rig.daemon->health();
    EXPECT_EQ(health["status"], "fault");
    EXPECT_NE(health["reasons"].dump().find("no ok result since"), std::string::npos) << health["reasons"];
}

TEST(Daemon, RefusedThenOkTheLevelFollowsTheMeasurement) {
    Rig rig({}, icewatch::test::freshTempDir(), [](ScriptedChain& c) {
        c.script = [](int call, const StereoPair&) {
            if (call == 1) return okResult(250.0);
            if (call <= 4) return refusedResult("current image blurred or without texture");
            return okResult(120.0);
        };
    });
    rig.daemon->runUntil(rig.at(2401));
    // Ice at 250 (alarm): refusals never lower it, the fourth cycle without a volume is a fault,
    // and the next volume sets the level again (120: warning, no hold times in the test config).
    EXPECT_EQ(alarmsOf(rig.daemon->history(testEpoch(), 100)),
              (std::vector<std::string>{"alarm", "alarm", "alarm", "fault", "warning"}));
    const nlohmann::json served = *rig.daemon->latest();
    EXPECT_EQ(served["alarm"], "warning");
    EXPECT_TRUE(served["alarm_reason"].is_null());
    EXPECT_EQ(served["last_ok"], "2026-01-01T00:40:00Z");
    EXPECT_FALSE(served["stale"].get<bool>());
    EXPECT_TRUE(served["stale_since"].is_null());
    EXPECT_EQ(alarmAndHealthy(rig.transitions()), std::make_pair(true, true));
}

TEST(Daemon, TheFaultComesAtMaxRefusedSEvenBetweenCyclesAndReachesScada) {
    Rig rig([](config::Config& c) { c.daemon.maxRefusedS = 900; }, icewatch::test::freshTempDir(),
            [](ScriptedChain& c) {
                c.script = [](int call, const StereoPair&) {
                    return call == 1 ? okResult(0.0) : refusedResult("12 % valid disparities in the region");
                };
            });
    RecordingSink sink;
    rig.daemon->setPublicationSink(&sink);
    rig.daemon->runUntil(rig.at(899));
    EXPECT_EQ(rig.latestFile()["alarm"], "none");
    rig.daemon->runUntil(rig.at(901));
    EXPECT_EQ(rig.daemon->history(testEpoch(), 100).size(), 2u) << "no cycle ran at 900 s";
    const nlohmann::json doc = rig.latestFile();
    EXPECT_EQ(doc["time"], "2026-01-01T00:10:00Z");
    EXPECT_EQ(doc["alarm"], "fault");
    EXPECT_NE(doc["alarm_reason"].get<std::string>().find("max_refused_s 900 s"), std::string::npos);
    ASSERT_FALSE(sink.seen.empty());
    EXPECT_EQ(sink.seen.back().document["alarm"], "fault") << "Modbus and MQTT are told as for any level";
    EXPECT_FALSE(sink.seen.back().newResult);
    EXPECT_EQ(alarmAndHealthy(rig.transitions()), std::make_pair(false, false));
    EXPECT_TRUE((*rig.daemon->latest())["stale"].get<bool>());
    EXPECT_EQ((*rig.daemon->latest())["stale_since"], "2026-01-01T00:15:00Z");
}

TEST(Daemon, FirstStartWithoutCalibrationOrGpioChipRunsReportsAndRetries) {
    const auto dir = icewatch::test::freshTempDir();
    ManualClock clock(testEpoch());
    config::Config config = testConfig(dir);
    auto gpioLog = std::make_shared<gpio::TransitionLog>();
    bool calibrated = false, chipThere = false;
    int chainAttempts = 0;
    DaemonParts parts;
    parts.source = std::make_unique<ScriptedSource>();
    parts.makeChain = [&]() -> std::unique_ptr<MeasurementChain> {
        ++chainAttempts;
        if (!calibrated) throw Error(kExitNoInput, "no calibration: run icewatch calibrate --out /etc/icewatch/c.yaml");
        return std::make_unique<ScriptedChain>();
    };
    parts.openOutputs = [&] {
        if (!chipThere) throw Error(kExitUnavailable, "no GPIO chip gpiochip0");
        return gpio::openScadaOutputs(config.gpio, gpioLog);
    };
    Daemon daemon(config, DaemonOptions{{}, "cafe", "v"}, clock, std::move(parts));
    daemon.runUntil(testEpoch() + std::chrono::seconds(1));
    nlohmann::json latest = *daemon.latest();
    EXPECT_EQ(latest["status"], "fault");
    EXPECT_EQ(latest["alarm"], "fault");
    EXPECT_EQ(latest["reason"], "no calibration: run icewatch calibrate --out /etc/icewatch/c.yaml; no GPIO chip gpiochip0");
    nlohmann::json health = daemon.health();
    EXPECT_EQ(health["status"], "fault");
    EXPECT_EQ(health["reasons"][0], "no calibration: run icewatch calibrate --out /etc/icewatch/c.yaml");
    EXPECT_EQ(health["reasons"][1], "no GPIO chip gpiochip0");

    const int attempts = chainAttempts;
    daemon.runUntil(testEpoch() + std::chrono::seconds(11));
    EXPECT_EQ(chainAttempts, attempts + 2) << "retried every camera_check_s (5 s)";
    EXPECT_TRUE(gpioLog->transitions().empty());

    // Installed, then SIGHUP: both arrive at once and a real measurement clears the fault.
    calibrated = chipThere = true;
    daemon.requestReload();
    daemon.runUntil(testEpoch() + std::chrono::seconds(12));
    latest = *daemon.latest();
    EXPECT_EQ(latest["status"], "ok");
    EXPECT_EQ(latest["alarm"], "alarm") << "the scripted chain's 1000 mm³";
    EXPECT_EQ(daemon.health()["reasons"], nlohmann::json::array());
    EXPECT_EQ(alarmAndHealthy(gpioLog->transitions()), std::make_pair(false, true));
}

}  // namespace never_silent

}  // namespace
}  // namespace icewatch::daemon::test
