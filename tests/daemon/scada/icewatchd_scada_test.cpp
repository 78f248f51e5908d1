// icewatchd as a process with both SCADA interfaces on, measuring the bundled recording through
// the fake camera, against a real mosquitto broker and libmodbus's client: retained results, the
// heartbeat, a coil, online/offline and the last will, and a broker that goes away mid-run.
#include <signal.h>

#include <cmath>
#include <fstream>
#include <thread>

#include <modbus.h>
#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include "core/calib/stereo_calibration.hpp"
#include "daemon/scada/modbus_server.hpp"
#include "tests/daemon/scada/scada_rig.hpp"
#include "tests/support/test_paths.hpp"

namespace icewatch::daemon::scada::test {
namespace {

struct Site {
    std::filesystem::path dir = icewatch::test::freshTempDir();
    Broker broker{dir};
    int modbusPort = freeLoopbackPort();
    std::string prefix = "test/" + dir.filename().string();

    // The demo recording (no baseline: every cycle is a quick no_baseline result), HTTP on any
    // port, and both SCADA interfaces.
    std::filesystem::path configFile() const {
        const auto calibration = dir / "calibration.yaml";
        calib::saveCalibration(calibration, calib::nominalCalibration({1280, 720}, 80.0, 60.0));
        const nlohmann::json config = {
            {"daemon", {{"interval_s", 600}, {"state_dir", (dir / "state").string()}}},
            {"calibration", {{"file", calibration.string()}}},
            {"camera", {{"device", "fake:" + (icewatch::test::sourceDir() / "tools/demo/recording").string()}}},
            {"gpio", {{"chip", "none"}}},
            {"http", {{"port", 0}}},
            {"scada",
             {{"modbus", {{"listen", "127.0.0.1:" + std::to_string(modbusPort)}, {"allow_writes", true}}},
              {"mqtt", {{"broker", broker.url()}, {"topic_prefix", prefix}, {"reconnect_max_s", 1}}}}}};
        std::ofstream(dir / "icewatch.json") << config.dump(2);
        return dir / "icewatch.json";
    }
    ChildProcess startDaemon() const {
        return ChildProcess({(icewatch::test::binDir() / "icewatchd").string(), "--config", configFile().string()},
                            dir / "icewatchd.log");
    }
    nlohmann::json latestFile() const {
        return nlohmann::json::parse(std::ifstream(dir / "state" / "latest.json"), nullptr, false);
    }
    std::string log() const { return readText(dir / "icewatchd.log"); }
    // The Modbus client, once the daemon listens.
    std::unique_ptr<ModbusClient> modbus() const {
        std::unique_ptr<ModbusClient> client;
        waitFor([&] {
            try {
                client = std::make_unique<ModbusClient>(modbusPort);
                return true;
            } catch (const std::runtime_error&) {
                return false;
            }
        });
        return client;
    }
};

std::uint32_t resultCount(ModbusClient& client) {
    const auto r = client.inputRegisters(kResultCountRegister, 2);
    return r.size() == 2 ? uint32At(r, 0) : 0;
}

bool sameJson(const std::string& payload, const nlohmann::json& document) {
    return nlohmann::json::parse(payload, nullptr, false) == document;
}

TEST(IcewatchdScada, PublishesRetainedResultsServesModbusAndSaysOfflineAtTheEnd) {
    Site s;
    s.broker.start();
    Subscriber subscriber(s.broker.port(), s.prefix + "/#");
    ChildProcess daemon = s.startDaemon();
    ASSERT_TRUE(subscriber.await(s.prefix + "/status", [](const std::string& p) { return p == "online"; }))
        << s.log();
    const auto latest = subscriber.await(s.prefix + "/latest");
    ASSERT_TRUE(latest) << s.log();
    const nlohmann::json file = s.latestFile();
    EXPECT_EQ(file["status"], "no_baseline");
    EXPECT_TRUE(sameJson(*latest, file)) << *latest << "\n" << file.dump(2);
    EXPECT_EQ(subscriber.await(s.prefix + "/alarm"), "fault");

    auto modbus = s.modbus();
    ASSERT_TRUE(modbus) << s.log();
    const auto registers = modbus->inputRegisters(0, 16);
    ASSERT_EQ(registers.size(), 16u);
    EXPECT_EQ(registers[kStatusRegister], 2) << "no baseline";
    EXPECT_EQ(registers[kAlarmLevelRegister], 3) << "fault: never shown as no ice";
    EXPECT_TRUE(std::isnan(floatAt(registers, kVolumeRegister)));
    EXPECT_EQ(uint32At(registers, kResultCountRegister), 1u);
    EXPECT_EQ(modbus->discreteInputs(0, 5), (std::vector<std::uint8_t>{0, 0, 1, 0, 0}));
    const auto beat = registers[kHeartbeatRegister];
    EXPECT_TRUE(waitFor([&] { return modbus->inputRegisters(kHeartbeatRegister, 1).at(0) != beat; }))
        << "the heartbeat counts while the loop runs";

    // Coil 0 is SIGUSR1: a new cycle, a new count, a new retained document.
    ASSERT_EQ(modbus->writeCoil(kMeasureNowCoil, true), 0);
    ASSERT_TRUE(waitFor([&] { return resultCount(*modbus) == 2; })) << s.log();
    const auto second = subscriber.await(s.prefix + "/latest", {}, 1);
    ASSERT_TRUE(second);
    EXPECT_TRUE(sameJson(*second, s.latestFile())) << *second;

    daemon.signal(SIGTERM);
    EXPECT_EQ(daemon.awaitExit(), 0) << s.log();
    EXPECT_TRUE(subscriber.await(s.prefix + "/status", [](const std::string& p) { return p == "offline"; }));
    // What a subscriber arriving later is told: the retained result and status.
    Subscriber late(s.broker.port(), s.prefix + "/#");
    const auto retained = late.await(s.prefix + "/latest");
    ASSERT_TRUE(retained);
    EXPECT_TRUE(sameJson(*retained, s.latestFile()));
    EXPECT_EQ(late.await(s.prefix + "/status"), "offline");
    s.broker.stop();
}

TEST(IcewatchdScada, TheLastWillSaysOfflineWhenTheDaemonDies) {
    Site s;
    s.broker.start();
    Subscriber subscriber(s.broker.port(), s.prefix + "/status");
    ChildProcess daemon = s.startDaemon();
    ASSERT_TRUE(subscriber.await(s.prefix + "/status", [](const std::string& p) { return p == "online"; }))
        << s.log();
    daemon.signal(SIGKILL);
    EXPECT_EQ(daemon.awaitExit(), 128 + SIGKILL);
    EXPECT_TRUE(subscriber.await(s.prefix + "/status", [](const std::string& p) { return p == "offline"; }))
        << "the broker publishes the will when the connection dies";
    s.broker.stop();
}

TEST(IcewatchdScada, ABrokerAwayMidRunStopsNoMeasurementAndGetsTheLatestWhenBack) {
    Site s;
    ChildProcess daemon = s.startDaemon();  // the broker is not there yet
    auto modbus = s.modbus();
    ASSERT_TRUE(modbus) << s.log();
    ASSERT_TRUE(waitFor([&] { return resultCount(*modbus) == 1; })) << "measured without a broker\n" << s.log();

    s.broker.start();
    {
        Subscriber subscriber(s.broker.port(), s.prefix + "/latest");
        const auto first = subscriber.await(s.prefix + "/latest");
        ASSERT_TRUE(first) << "published once the broker came\n" << s.log();
        EXPECT_TRUE(sameJson(*first, s.latestFile()));
    }

    s.broker.stop();
    for (std::uint32_t count = 2; count <= 3; ++count) {
        daemon.signal(SIGUSR1);
        ASSERT_TRUE(waitFor([&] { return resultCount(*modbus) == count; })) << "measuring goes on\n" << s.log();
    }
    const nlohmann::json during = s.latestFile();
    // Long enough for several reconnect attempts (back-off at most 1 s here).
    std::this_thread::sleep_for(std::chrono::seconds(3));
    EXPECT_TRUE(daemon.running());

    s.broker.start();  // a fresh broker: it kept nothing
    Subscriber subscriber(s.broker.port(), s.prefix + "/#");
    const auto latest = subscriber.await(s.prefix + "/latest");
    ASSERT_TRUE(latest) << s.log();
    EXPECT_TRUE(sameJson(*latest, during)) << "the result measured while the broker was away";
    EXPECT_EQ(subscriber.await(s.prefix + "/status"), "online");

    EXPECT_EQ(occurrences(s.log(), "Connection refused"), 2u)
        << "once before the broker first came, once while it was away, not per attempt\n" << s.log();
    daemon.signal(SIGTERM);
    EXPECT_EQ(daemon.awaitExit(), 0) << s.log();
    s.broker.stop();
}

TEST(IcewatchdScada, AModbusPortInUseStopsTheStartWithStatus69) {
    Site s;
    ModbusServer occupant({"127.0.0.1:" + std::to_string(s.modbusPort), 1, false}, {});
    ChildProcess daemon = s.startDaemon();
    EXPECT_EQ(daemon.awaitExit(), 69) << "EX_UNAVAILABLE: systemd restarts it later\n" << s.log();
    EXPECT_NE(s.log().find("cannot listen on 127.0.0.1:" + std::to_string(s.modbusPort)), std::string::npos)
        << s.log();
}

}  // namespace
}  // namespace icewatch::daemon::scada::test
