// The "scada" section and the two address forms it holds. The addresses are checked here so a
// typo stops the daemon at start with the key named, instead of surfacing as a socket error.
#include "core/config/scada_section.hpp"

#include <charconv>

namespace icewatch::config {

namespace {

std::optional<int> parsePort(std::string_view text) {
    int port = -1;
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), port);
    if (text.empty() || error != std::errc() || end != text.data() + text.size() || port < 0 || port > 65535) {
        return std::nullopt;
    }
    return port;
}

// "host:port" or "[v6]:port"; the port may be absent when defaultPort is given.
std::optional<ListenAddress> splitHostPort(std::string_view text, std::optional<int> defaultPort) {
    std::string_view host;
    std::string_view rest;
    if (!text.empty() && text.front() == '[') {
        const auto close = text.find(']');
        if (close == std::string_view::npos) return std::nullopt;
        host = text.substr(1, close - 1);
        rest = text.substr(close + 1);
    } else {
        const auto colon = text.find(':');
        host = text.substr(0, colon);
        rest = colon == std::string_view::npos ? std::string_view() : text.substr(colon);
    }
    if (host.empty() || host.find_first_of("/[]@ ") != std::string_view::npos) return std::nullopt;
    std::optional<int> port = defaultPort;
    if (!rest.empty()) {
        if (rest.front() != ':') return std::nullopt;
        port = parsePort(rest.substr(1));
    }
    if (!port) return std::nullopt;
    return ListenAddress{std::string(host), *port};
}

void readModbus(Section s, ModbusConfig& modbus) {
    s.read("listen", modbus.listen);
    if (!modbus.listen.empty() && !parseListenAddress(modbus.listen)) {
        s.reject("listen", "must be host:port (\"127.0.0.1:1502\", \"[::1]:1502\") or empty (off), got \"" +
                             modbus.listen + "\"");
    }
    s.read("unit_id", modbus.unitId, 1, 247);
    s.read("allow_writes", modbus.allowWrites);
    s.finish();
}

void readMqtt(Section s, MqttConfig& mqtt) {
    s.read("broker", mqtt.broker);
    if (!mqtt.broker.empty() && !parseBrokerUrl(mqtt.broker)) {
        s.reject("broker", "must be mqtt://host[:port] or mqtts://host[:port] or empty (off), got \"" + mqtt.broker +
                             "\"");
    }
    s.read("client_id", mqtt.clientId);
    s.read("username", mqtt.username);
    s.read("password_file", mqtt.passwordFile);
    if (!mqtt.passwordFile.empty() && mqtt.username.empty()) {
        s.reject("password_file", "needs username (MQTT sends no password without a user name)");
    }
    s.read("ca_file", mqtt.caFile);
    s.read("topic_prefix", mqtt.topicPrefix);
    if (mqtt.topicPrefix.find_first_of("+#") != std::string::npos || mqtt.topicPrefix.find('\0') != std::string::npos ||
        (!mqtt.topicPrefix.empty() && mqtt.topicPrefix.back() == '/')) {
        s.reject("topic_prefix", "must be a topic without wildcards (+, #) or a trailing /, got \"" + mqtt.topicPrefix +
                                   "\"");
    }
    s.read("qos", mqtt.qos, 0, 2);
    s.read("reconnect_max_s", mqtt.reconnectMaxS, 1, 3600);
    s.finish();
}

}  // namespace

std::optional<ListenAddress> parseListenAddress(const std::string& text) {
    return splitHostPort(text, std::nullopt);
}

std::optional<BrokerAddress> parseBrokerUrl(const std::string& url) {
    BrokerAddress broker;
    std::string_view rest(url);
    if (rest.starts_with("mqtt://")) {
        rest.remove_prefix(7);
    } else if (rest.starts_with("mqtts://")) {
        rest.remove_prefix(8);
        broker.tls = true;
    } else {
        return std::nullopt;
    }
    if (!rest.empty() && rest.back() == '/') rest.remove_suffix(1);
    const auto hostPort = splitHostPort(rest, broker.tls ? 8883 : 1883);
    if (!hostPort || hostPort->port == 0) return std::nullopt;
    broker.host = hostPort->host;
    broker.port = hostPort->port;
    return broker;
}

void readScada(Section s, ScadaConfig& scada) {
    readModbus(s.child("modbus"), scada.modbus);
    readMqtt(s.child("mqtt"), scada.mqtt);
    s.finish();
}

}  // namespace icewatch::config
