#pragma once

#include <optional>
#include <string>

namespace icewatch::config {

// The "scada" section: Modbus TCP and MQTT, both off by default (config/icewatch.json documents
// every key). Taken at start; a reload leaves them as they are.

struct ModbusConfig {
    std::string listen;       // "127.0.0.1:1502", "[::1]:1502", "0.0.0.0:1502"; empty: off; port 0: any free port
    int unitId = 1;           // the unit identifier this server answers (and 255, "this device")
    bool allowWrites = false; // coils 0 (measure now) and 1 (reset a latched alarm); off: illegal function
};

struct MqttConfig {
    std::string broker;        // mqtt://host[:1883] or mqtts://host[:8883]; empty: off
    std::string clientId;      // empty: icewatch-<hostname>
    std::string username;      // empty: anonymous
    std::string passwordFile;  // its first line is the password; empty: none
    std::string caFile;        // mqtts: the CA that signed the broker's certificate; empty: the system's
    std::string topicPrefix;   // empty: icewatch/<hostname>
    int qos = 1;
    int reconnectMaxS = 60;    // reconnect back-off doubles from 1 s up to this
};

struct ScadaConfig {
    ModbusConfig modbus;
    MqttConfig mqtt;
};

// host and port of scada.modbus.listen; nullopt when it is not host:port.
struct ListenAddress {
    std::string host;  // without IPv6 brackets
    int port = 0;
};
std::optional<ListenAddress> parseListenAddress(const std::string& text);

// scada.mqtt.broker taken apart; nullopt when it is not mqtt:// or mqtts:// host[:port].
struct BrokerAddress {
    bool tls = false;
    std::string host;
    int port = 0;
};
std::optional<BrokerAddress> parseBrokerUrl(const std::string& url);

}  // namespace icewatch::config
