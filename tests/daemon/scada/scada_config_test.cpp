// The "scada" configuration section: off by default, the shipped file agrees, and every mistake
// stops with the key named.
#include <gtest/gtest.h>

#include "core/config/config.hpp"
#include "core/config/section.hpp"
#include "tests/support/test_paths.hpp"

namespace icewatch::config {
namespace {

std::string errorOf(const std::string& scada) {
    try {
        parseConfig(R"({"scada": )" + scada + "}", "test.json");
    } catch (const ConfigError& e) {
        EXPECT_EQ(e.code(), kExitConfig);
        return e.what();
    }
    return "";
}

TEST(ScadaConfig, BothOffByDefaultAndTheShippedFileSaysSo) {
    const Config defaults = parseConfig("{}", "defaults");
    EXPECT_EQ(defaults.scada.modbus.listen, "");
    EXPECT_EQ(defaults.scada.mqtt.broker, "");
    EXPECT_EQ(defaults.scada.modbus.unitId, 1);
    EXPECT_FALSE(defaults.scada.modbus.allowWrites);
    EXPECT_EQ(defaults.scada.mqtt.qos, 1);

    const Config shipped = loadConfig(test::sourceDir() / "config" / "icewatch.json");
    const ScadaConfig& a = shipped.scada;
    const ScadaConfig& b = defaults.scada;
    EXPECT_EQ(a.modbus.listen, b.modbus.listen);
    EXPECT_EQ(a.modbus.unitId, b.modbus.unitId);
    EXPECT_EQ(a.modbus.allowWrites, b.modbus.allowWrites);
    EXPECT_EQ(a.mqtt.broker, b.mqtt.broker);
    EXPECT_EQ(a.mqtt.clientId, b.mqtt.clientId);
    EXPECT_EQ(a.mqtt.username, b.mqtt.username);
    EXPECT_EQ(a.mqtt.passwordFile, b.mqtt.passwordFile);
    EXPECT_EQ(a.mqtt.caFile, b.mqtt.caFile);
    EXPECT_EQ(a.mqtt.topicPrefix, b.mqtt.topicPrefix);
    EXPECT_EQ(a.mqtt.qos, b.mqtt.qos);
    EXPECT_EQ(a.mqtt.reconnectMaxS, b.mqtt.reconnectMaxS);
}

TEST(ScadaConfig, ReadsEveryKey) {
    const Config c = parseConfig(R"({"scada": {
        "modbus": {"listen": "0.0.0.0:1502", "unit_id": 7, "allow_writes": true},
        "mqtt": {"broker": "mqtts://broker.example:8884", "client_id": "tower-3", "username": "u",
                 "password_file": "/etc/icewatch/mqtt.pw", "ca_file": "/etc/icewatch/ca.pem",
                 "topic_prefix": "farm/t3", "qos": 2, "reconnect_max_s": 5}}})",
                                 "test.json");
    EXPECT_EQ(c.scada.modbus.listen, "0.0.0.0:1502");
    EXPECT_EQ(c.scada.modbus.unitId, 7);
    EXPECT_TRUE(c.scada.modbus.allowWrites);
    EXPECT_EQ(c.scada.mqtt.broker, "mqtts://broker.example:8884");
    EXPECT_EQ(c.scada.mqtt.clientId, "tower-3");
    EXPECT_EQ(c.scada.mqtt.username, "u");
    EXPECT_EQ(c.scada.mqtt.passwordFile, "/etc/icewatch/mqtt.pw");
    EXPECT_EQ(c.scada.mqtt.caFile, "/etc/icewatch/ca.pem");
    EXPECT_EQ(c.scada.mqtt.topicPrefix, "farm/t3");
    EXPECT_EQ(c.scada.mqtt.qos, 2);
    EXPECT_EQ(c.scada.mqtt.reconnectMaxS, 5);
}

TEST(ScadaConfig, Addresses) {
    const auto v4 = parseListenAddress("127.0.0.1:1502");
    ASSERT_TRUE(v4);
    EXPECT_EQ(v4->host, "127.0.0.1");
    EXPECT_EQ(v4->port, 1502);
    const auto v6 = parseListenAddress("[::1]:0");
    ASSERT_TRUE(v6);
    EXPECT_EQ(v6->host, "::1");
    EXPECT_EQ(v6->port, 0);
    for (const char* bad : {"127.0.0.1", "127.0.0.1:", ":1502", "::1:1502", "127.0.0.1:65536", "host:12x", "[::1"}) {
        EXPECT_FALSE(parseListenAddress(bad)) << bad;
    }

    const auto plain = parseBrokerUrl("mqtt://127.0.0.1");
    ASSERT_TRUE(plain);
    EXPECT_FALSE(plain->tls);
    EXPECT_EQ(plain->host, "127.0.0.1");
    EXPECT_EQ(plain->port, 1883);
    const auto tls = parseBrokerUrl("mqtts://broker.example/");
    ASSERT_TRUE(tls);
    EXPECT_TRUE(tls->tls);
    EXPECT_EQ(tls->port, 8883);
    EXPECT_EQ(parseBrokerUrl("mqtt://[::1]:1884")->host, "::1");
    for (const char* bad : {"tcp://host:1883", "host:1883", "mqtt://", "mqtt://host:0", "mqtt://user@host"}) {
        EXPECT_FALSE(parseBrokerUrl(bad)) << bad;
    }
}

TEST(ScadaConfig, MistakesNameTheKey) {
    EXPECT_NE(errorOf(R"({"modbus": {"listen": "1502"}})").find("test.json: scada.modbus.listen: must be host:port"),
              std::string::npos);
    EXPECT_NE(errorOf(R"({"modbus": {"unit_id": 0}})").find("scada.modbus.unit_id: must be between 1 and 247"),
              std::string::npos);
    EXPECT_NE(errorOf(R"({"modbus": {"lisen": "127.0.0.1:1502"}})").find("scada.modbus.lisen"), std::string::npos);
    EXPECT_NE(errorOf(R"({"mqtt": {"broker": "tcp://host"}})").find("scada.mqtt.broker: must be mqtt://"),
              std::string::npos);
    EXPECT_NE(errorOf(R"({"mqtt": {"qos": 3}})").find("scada.mqtt.qos: must be between 0 and 2"), std::string::npos);
    EXPECT_NE(errorOf(R"({"mqtt": {"topic_prefix": "farm/+"}})").find("scada.mqtt.topic_prefix: must be a topic"),
              std::string::npos);
    EXPECT_NE(errorOf(R"({"mqtt": {"topic_prefix": "farm/"}})").find("scada.mqtt.topic_prefix"), std::string::npos);
    EXPECT_NE(errorOf(R"({"mqtt": {"password_file": "/p"}})").find("scada.mqtt.password_file: needs username"),
              std::string::npos);
    EXPECT_NE(errorOf(R"({"modem": {}})").find("scada.modem"), std::string::npos);
}

}  // namespace
}  // namespace icewatch::config
