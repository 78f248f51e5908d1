// latest.json's atomic replacement, ISO times, history rows and CSV.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>

#include <sqlite3.h>

#include <gtest/gtest.h>

#include "core/common/error.hpp"
#include "daemon/atomic_file.hpp"
#include "daemon/baseline_store.hpp"
#include "daemon/cycle_result.hpp"
#include "daemon/history.hpp"
#include "daemon/iso_time.hpp"
#include "tests/daemon/rig.hpp"

namespace icewatch::daemon::test {
namespace {

std::string readFile(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

TEST(BaselineStore, TheNoiseDrawIsKeptSignedToAFractionOfAGreyLevel) {
    const auto dir = icewatch::test::freshTempDir();
    BaselineRecord record{testEpoch(), "c0ffee", {}, "test", {}};
    cv::RNG rng(5);
    for (cv::Mat* eye : {&record.pair.left, &record.pair.right, &record.noise.left, &record.noise.right}) {
        *eye = cv::Mat(48, 64, CV_32F);
        rng.fill(*eye, cv::RNG::UNIFORM, 0.0, 255.0);
    }
    rng.fill(record.noise.left, cv::RNG::NORMAL, 0.0, 0.4);
    rng.fill(record.noise.right, cv::RNG::NORMAL, 0.0, 0.4);
    std::string error;
    ASSERT_TRUE(saveBaseline(dir, record, error)) << error;
    auto loaded = loadBaseline(dir, error);
    ASSERT_TRUE(loaded) << error;
    ASSERT_EQ(loaded->noise.left.size(), record.noise.left.size());
    EXPECT_LE(cv::norm(loaded->noise.left, record.noise.left, cv::NORM_INF), 0.51 / 256.0);
    EXPECT_LE(cv::norm(loaded->noise.right, record.noise.right, cv::NORM_INF), 0.51 / 256.0);

    // A record kept before the draw was stored loads without one.
    nlohmann::json doc = nlohmann::json::parse(readFile(dir / "baseline" / "baseline.json"));
    const std::string noiseLeft = doc["noise_left"];
    doc.erase("noise_left");
    doc.erase("noise_right");
    std::ofstream(dir / "baseline" / "baseline.json") << doc.dump();
    loaded = loadBaseline(dir, error);
    ASSERT_TRUE(loaded) << error;
    EXPECT_TRUE(loaded->noise.left.empty());

    // One named but gone is an error that names it, not a reference read without it.
    doc["noise_left"] = noiseLeft;
    doc["noise_right"] = "noise-right-gone.png";
    std::ofstream(dir / "baseline" / "baseline.json") << doc.dump();
    EXPECT_FALSE(loadBaseline(dir, error));
    EXPECT_NE(error.find("noise-right-gone.png"), std::string::npos) << error;
    doc.erase("noise_right");
    std::ofstream(dir / "baseline" / "baseline.json") << doc.dump();
    EXPECT_FALSE(loadBaseline(dir, error));
    EXPECT_NE(error.find("noise_right"), std::string::npos) << error;
}

TEST(AtomicFile, AKillDuringWritesLeavesTheOldOrTheNewDocument) {
    // A writer process replaces latest.json with two different large documents in turn until it
    // is killed; whenever the kill lands, the file must be one of the two, whole.
    const auto dir = icewatch::test::freshTempDir();
    const auto path = dir / "latest.json";
    const std::string a = nlohmann::json{{"doc", "a"}, {"pad", std::string(200000, 'a')}}.dump();
    const std::string b = nlohmann::json{{"doc", "b"}, {"pad", std::string(300000, 'b')}}.dump();
    ASSERT_TRUE(writeFileAtomically(path, a));
    for (int round = 0; round < 8; ++round) {
        int ready[2];
        ASSERT_EQ(::pipe(ready), 0);
        const pid_t pid = ::fork();
        ASSERT_GE(pid, 0);
        if (pid == 0) {
            ::close(ready[0]);
            for (long i = 0;; ++i) {
                writeFileAtomically(path, i % 2 == 0 ? b : a, Durability::AtomicOnly);
                if (i == 3 + round) (void)!::write(ready[1], "x", 1);  // mid-stream from here on
            }
        }
        ::close(ready[1]);
        char c;
        ASSERT_EQ(::read(ready[0], &c, 1), 1);
        ::close(ready[0]);
        ::kill(pid, SIGKILL);
        int status = 0;
        ::waitpid(pid, &status, 0);
        const std::string content = readFile(path);
        EXPECT_TRUE(content == a || content == b) << "round " << round << ": " << content.size() << " bytes";
        removeStaleTemporaries(dir);
    }
    std::size_t files = 0;
    for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir)) ++files;
    EXPECT_EQ(files, 1u) << "temporaries of killed writers are cleaned up";
}

TEST(AtomicFile, FailsWithoutTouchingTheTarget) {
    EXPECT_FALSE(writeFileAtomically("/nonexistent-dir/latest.json", "{}"));
}

TEST(IsoTime, FormatsAndParses) {
    const auto t = *parseIsoUtc("2026-03-04T05:06:07Z");
    EXPECT_EQ(formatIsoUtc(t), "2026-03-04T05:06:07Z");
    EXPECT_EQ(formatIsoUtc(*parseIsoUtc("2026-03-04")), "2026-03-04T00:00:00Z");
    EXPECT_EQ(formatIsoUtc(*parseIsoUtc("2026-03-04T05:06:07+02:00")), "2026-03-04T03:06:07Z");
    EXPECT_EQ(formatIsoUtc(*parseIsoUtc("2026-03-04T05:06:07.900Z")), "2026-03-04T05:06:07Z");
    EXPECT_EQ(formatIsoUtc(*parseIsoUtc("2026-03-04 05:06")), "2026-03-04T05:06:00Z");
    for (const char* bad : {"", "yesterday", "2026-13-01", "2026-02-29", "2026-01-01T24:00:00Z", "2026-01-01T00:00:00+25:00",
                            "2026-01-01T00:00:00Zjunk", "20260101"}) {
        EXPECT_FALSE(parseIsoUtc(bad)) << bad;
    }
}

TEST(History, RowsCarryTheResultFields) {
    const auto dir = icewatch::test::freshTempDir();
    CycleResult r;
    r.time = testEpoch();
    r.status = CycleStatus::Refused;
    r.reason = "fog, \"thick\"";
    r.alarm = alarm::AlarmLevel::Warning;
    r.camera = CameraState::Degraded;
    r.quality = {{"low_contrast", "frame 1 left: grey-level deviation 2.0 below 6.0"}};
    r.timingsMs = {{"grab", 3.5}};
    r.version = "1.2.3";
    r.configSha256 = "abc";
    r.alarmReason = "no ok result since 2025-12-31T23:00:00Z";
    r.lastOk = testEpoch() - std::chrono::hours(1);
    {
        History history(dir / "h.sqlite");
        ASSERT_TRUE(history.append(r));
        r.time += std::chrono::minutes(10);
        r.status = CycleStatus::Ok;
        r.reason.clear();
        r.alarmReason.clear();
        r.lastOk = r.time;
        r.volumeMm3 = 1234.5;
        r.uncertaintyMm3 = 50;
        r.meanThicknessMm = 1.5;
        r.meanThicknessUncertaintyMm = 0.06;
        r.maxThicknessMm = 4;
        r.iceAreaMm2 = 823;
        r.beyondOutlineMm3 = 12.5;
        r.validPercent = 88;
        ASSERT_TRUE(history.append(r));
    }
    History readOnly(dir / "h.sqlite", History::Mode::ReadOnly);
    const auto rows = readOnly.since(testEpoch(), 10);
    ASSERT_EQ(rows.size(), 2u);
    EXPECT_EQ(rows[0], toJson([&] {
                  CycleResult first = r;
                  first.time = testEpoch();
                  first.status = CycleStatus::Refused;
                  first.reason = "fog, \"thick\"";
                  first.alarmReason = "no ok result since 2025-12-31T23:00:00Z";
                  first.lastOk = testEpoch() - std::chrono::hours(1);
                  first.volumeMm3.reset();
                  first.uncertaintyMm3.reset();
                  first.meanThicknessMm.reset();
                  first.meanThicknessUncertaintyMm.reset();
                  first.maxThicknessMm.reset();
                  first.iceAreaMm2.reset();
                  first.beyondOutlineMm3.reset();
                  first.validPercent.reset();
                  return first;
              }()));
    EXPECT_EQ(rows[1], toJson(r));
    EXPECT_EQ(readOnly.since(testEpoch() + std::chrono::minutes(5), 10).size(), 1u);
    EXPECT_EQ(historyCsvHeader(),
              "time,status,reason,volume_mm3,uncertainty_mm3,mean_thickness_mm,mean_thickness_uncertainty_mm,"
              "max_thickness_mm,ice_area_mm2,"
              "beyond_outline_mm3,valid_percent,alarm,camera,quality,version,config_sha256");
    EXPECT_EQ(historyCsvLine(rows[0]),
              "2026-01-01T00:00:00Z,refused,\"fog, \"\"thick\"\"\",,,,,,,,,warning,degraded,low_contrast: frame 1 left: "
              "grey-level deviation 2.0 below 6.0,1.2.3,abc");
    EXPECT_EQ(historyCsvLine(rows[1]).substr(0, 65), "2026-01-01T00:10:00Z,ok,,1234.5,50.0,1.5,0.06,4.0,823.0,12.5,88.0");
    EXPECT_THROW(History(dir / "missing.sqlite", History::Mode::ReadOnly), Error);
}

TEST(History, AHistoryOfTheFirstLayoutGainsTheNewColumns) {
    const auto dir = icewatch::test::freshTempDir();
    const auto file = dir / "h.sqlite";
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open(file.c_str(), &db), SQLITE_OK);
    // The layout before alarm_reason and last_ok, with one row in it.
    ASSERT_EQ(sqlite3_exec(db, R"(CREATE TABLE results (id INTEGER PRIMARY KEY, schema INTEGER NOT NULL,
        time_unix INTEGER NOT NULL, time TEXT NOT NULL, status TEXT NOT NULL, reason TEXT, volume_mm3 REAL,
        uncertainty_mm3 REAL, mean_thickness_mm REAL, max_thickness_mm REAL, valid_percent REAL,
        alarm TEXT NOT NULL, camera TEXT NOT NULL, quality TEXT NOT NULL, timings_ms TEXT NOT NULL,
        version TEXT NOT NULL, config_sha256 TEXT NOT NULL);
        INSERT INTO results VALUES (1, 1, 1767225600, '2026-01-01T00:00:00Z', 'ok', NULL, 5.0, 1.0, 0.1, 0.2,
        90.0, 'none', 'ok', '{}', '{}', '0.1.0', 'abc');)",
                           nullptr, nullptr, nullptr),
              SQLITE_OK);
    sqlite3_close(db);
    History history(file);
    CycleResult r;
    r.time = testEpoch() + std::chrono::minutes(10);
    r.status = CycleStatus::Refused;
    r.alarmReason = "no ok result since 2026-01-01T00:00:00Z";
    r.lastOk = testEpoch();
    ASSERT_TRUE(history.append(r));
    EXPECT_TRUE(history.recovery().empty()) << "an old layout is not damage";
    const auto rows = history.since(testEpoch(), 10);
    ASSERT_EQ(rows.size(), 2u);
    EXPECT_TRUE(rows[0]["last_ok"].is_null());
    EXPECT_EQ(rows[0]["volume_mm3"], 5.0);
    EXPECT_EQ(rows[1]["alarm_reason"], "no ok result since 2026-01-01T00:00:00Z");
    EXPECT_EQ(rows[1]["last_ok"], "2026-01-01T00:00:00Z");
    EXPECT_TRUE(rows[0]["ice_area_mm2"].is_null());
    EXPECT_TRUE(rows[0]["mean_thickness_uncertainty_mm"].is_null());
    // The added figures are numbers in the old file too, not the text an untyped column would keep.
    r.time += std::chrono::minutes(10);
    r.status = CycleStatus::Ok;
    r.iceAreaMm2 = 823.5;
    r.meanThicknessUncertaintyMm = 0.25;
    ASSERT_TRUE(history.append(r));
    EXPECT_EQ(history.since(testEpoch(), 10)[2]["ice_area_mm2"], 823.5);
    EXPECT_EQ(history.since(testEpoch(), 10)[2]["mean_thickness_uncertainty_mm"], 0.25);
}

}  // namespace
}  // namespace icewatch::daemon::test
