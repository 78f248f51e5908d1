// The MQTT publisher on its own against a real mosquitto: TLS with a CA of the test's making and a
// password, the refusals a tower meets in the field (a wrong password, a broker it must not
// trust) logged once while it keeps trying, and configuration mistakes that stop it at start.
#include "daemon/scada/mqtt_publisher.hpp"

#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>

#include <fstream>
#include <sstream>
#include <thread>

#include "core/common/error.hpp"
#include "tests/daemon/scada/scada_rig.hpp"
#include "tests/support/run_program.hpp"
#include "tests/support/test_paths.hpp"

namespace icewatch::daemon::scada::test {
namespace {

// A CA and a certificate for 127.0.0.1 signed by it (EC keys: quick to make).
void makeCertificates(const std::filesystem::path& dir, const std::string& ca) {
    auto run = [](std::vector<std::string> argv) {
        const auto result = icewatch::test::runProgram(argv);
        ASSERT_EQ(result.status, 0) << argv[1] << ": " << result.err;
    };
    const std::string key = "ec", curve = "ec_paramgen_curve:prime256v1";
    run({"/usr/bin/openssl", "req", "-x509", "-newkey", key, "-pkeyopt", curve, "-nodes", "-days", "2", "-subj",
         "/CN=" + ca, "-keyout", (dir / (ca + ".key")).string(), "-out", (dir / (ca + ".pem")).string()});
    if (ca != "icewatch-test-ca") return;
    std::ofstream(dir / "san.ext") << "subjectAltName=IP:127.0.0.1\n";
    run({"/usr/bin/openssl", "req", "-newkey", key, "-pkeyopt", curve, "-nodes", "-subj", "/CN=127.0.0.1", "-keyout",
         (dir / "server.key").string(), "-out", (dir / "server.csr").string()});
    run({"/usr/bin/openssl", "x509", "-req", "-in", (dir / "server.csr").string(), "-CA", (dir / (ca + ".pem")).string(),
         "-CAkey", (dir / (ca + ".key")).string(), "-CAcreateserial", "-days", "2", "-extfile",
         (dir / "san.ext").string(), "-out", (dir / "server.pem").string()});
}

// A broker with a second listener for TLS and passwords (tower/secret); the test's subscriber
// uses the plain one.
struct TlsSite {
    TlsSite() {
        makeCertificates(dir, "icewatch-test-ca");
        makeCertificates(dir, "some-other-ca");
        const auto passwd = icewatch::test::runProgram(
            {"/usr/bin/mosquitto_passwd", "-b", "-c", (dir / "passwd").string(), "tower", "secret"});
        EXPECT_EQ(passwd.status, 0) << passwd.err;
        std::filesystem::permissions(dir / "server.key", std::filesystem::perms::owner_read |
                                                             std::filesystem::perms::group_read |
                                                             std::filesystem::perms::others_read);
        std::ofstream(dir / "right") << "secret\n";
        std::ofstream(dir / "wrong") << "guess\n";
        std::ostringstream extra;
        extra << "password_file " << (dir / "passwd").string() << "\nlistener " << tlsPort << " 127.0.0.1\ncafile "
              << (dir / "icewatch-test-ca.pem").string() << "\ncertfile " << (dir / "server.pem").string()
              << "\nkeyfile " << (dir / "server.key").string() << "\n";
        broker.emplace(dir, extra.str());
        broker->start();
    }
    config::MqttConfig publisher(const std::string& prefix, const std::string& password, const std::string& ca) const {
        config::MqttConfig c;
        c.broker = "mqtts://127.0.0.1:" + std::to_string(tlsPort);
        c.username = "tower";
        c.passwordFile = (dir / password).string();
        c.caFile = (dir / (ca + ".pem")).string();
        c.topicPrefix = prefix;
        c.reconnectMaxS = 1;
        return c;
    }

    std::filesystem::path dir = icewatch::test::freshTempDir();
    int tlsPort = freeLoopbackPort();
    std::optional<Broker> broker;
};

const nlohmann::json kDocument = {{"time", "2026-01-01T00:10:00Z"}, {"status", "ok"}, {"volume_mm3", 1234.5},
                                  {"alarm", "warning"}};

TEST(MqttPublisher, OverTlsWithAPasswordPublishesRetainedAndSaysOfflineAtTheEnd) {
    TlsSite site;
    Subscriber subscriber(site.broker->port(), "tower/#");
    {
        MqttPublisher publisher(site.publisher("tower", "right", "icewatch-test-ca"), "host");
        publisher.publish(kDocument);
        ASSERT_EQ(subscriber.await("tower/status"), "online");
        const auto latest = subscriber.await("tower/latest");
        ASSERT_TRUE(latest);
        EXPECT_EQ(nlohmann::json::parse(*latest), kDocument);
        EXPECT_EQ(subscriber.await("tower/alarm"), "warning");
    }
    EXPECT_TRUE(subscriber.await("tower/status", [](const std::string& p) { return p == "offline"; }));
    EXPECT_EQ(subscriber.payloads("tower/latest").size(), 1u) << "one result, published once";
}

TEST(MqttPublisher, AWrongPasswordOrAnUntrustedBrokerIsRefusedAndLoggedOnceWhileItKeepsTrying) {
    TlsSite site;
    std::ostringstream lines;
    auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(lines);
    log::get("mqtt")->sinks().push_back(sink);
    Subscriber subscriber(site.broker->port(), "#");
    {
        MqttPublisher wrongPassword(site.publisher("wrong-password", "wrong", "icewatch-test-ca"), "host");
        MqttPublisher untrusted(site.publisher("untrusted", "right", "some-other-ca"), "host");
        wrongPassword.publish(kDocument);
        untrusted.publish(kDocument);
        // Long enough for several attempts each (back-off at most 1 s).
        std::this_thread::sleep_for(std::chrono::milliseconds(3500));
    }
    log::get("mqtt")->sinks().pop_back();
    EXPECT_TRUE(subscriber.payloads("wrong-password/latest").empty());
    EXPECT_TRUE(subscriber.payloads("untrusted/latest").empty());
    const std::string log = lines.str();
    EXPECT_EQ(occurrences(log, "the broker refused the connection: Connection Refused: not authorised;"), 1u) << log;
    EXPECT_EQ(occurrences(log, "A TLS error occurred;"), 1u) << log;
    const std::string attempts = readText(site.dir / "mosquitto.log");
    const std::size_t connections = occurrences(attempts, "on port " + std::to_string(site.tlsPort));
    EXPECT_GE(connections, 6u) << "both kept trying, about once a second\n" << attempts;
}

// What a publisher of c stops with at start: exit code and message; {0, ""} when it starts.
std::pair<int, std::string> startError(const config::MqttConfig& c) {
    try {
        MqttPublisher publisher(c, "host");
    } catch (const Error& e) {
        return {e.code(), e.what()};
    }
    return {0, ""};
}

TEST(MqttPublisher, MissingFilesStopItAtStartAndTheDefaultsUseTheHostname) {
    config::MqttConfig c;
    c.broker = "mqtts://127.0.0.1:8883";
    c.username = "tower";
    c.passwordFile = "/nonexistent/password";
    EXPECT_EQ(startError(c), std::make_pair(int(kExitConfig), std::string("scada.mqtt.password_file: cannot read "
                                                                          "/nonexistent/password")));
    c.passwordFile.clear();
    c.caFile = "/nonexistent/ca.pem";
    EXPECT_EQ(startError(c),
              std::make_pair(int(kExitConfig), std::string("scada.mqtt.ca_file: cannot read /nonexistent/ca.pem")));
    c.caFile.clear();
    c.broker = "mqtt://127.0.0.1:" + std::to_string(freeLoopbackPort());
    MqttPublisher publisher(c, "tower-3");
    EXPECT_EQ(publisher.topicPrefix(), "icewatch/tower-3");
}

}  // namespace
}  // namespace icewatch::daemon::scada::test
