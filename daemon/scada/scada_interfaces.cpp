// Wires the SCADA interfaces to the daemon: publications in, requests and the stale judgement
// out. The result counter lives here so both interfaces and every register see one count.
#include "daemon/scada/scada_interfaces.hpp"

#include <unistd.h>

#include <climits>

#include "daemon/daemon.hpp"

namespace icewatch::daemon::scada {

std::string hostName() {
    char name[HOST_NAME_MAX + 1] = {};
    if (::gethostname(name, sizeof name - 1) != 0 || name[0] == '\0') return "localhost";
    return name;
}

ScadaInterfaces::ScadaInterfaces(const config::ScadaConfig& config, Daemon& daemon, const LoopHeartbeat* heartbeat,
                                 const ModbusLimits& modbusLimits) {
    if (!config.modbus.listen.empty()) {
        ModbusHooks hooks;
        hooks.measureNow = [&daemon] { daemon.requestMeasure(); };
        hooks.resetAlarm = [&daemon] { daemon.requestAlarmReset(); };
        hooks.loopAlive = [heartbeat] { return heartbeat != nullptr && heartbeat->alive(std::chrono::steady_clock::now()); };
        hooks.resultStale = [&daemon] {
            const auto latest = daemon.latest();
            return !latest || latest->value("stale", true);
        };
        modbus_ = std::make_unique<ModbusServer>(config.modbus, std::move(hooks), modbusLimits);
        modbusHost_ = config::parseListenAddress(config.modbus.listen)->host;
    }
    if (!config.mqtt.broker.empty()) {
        mqtt_ = std::make_unique<MqttPublisher>(config.mqtt, hostName());
        broker_ = config.mqtt.broker;
    }
}

void ScadaInterfaces::published(const Publication& publication) {
    if (publication.newResult) ++results_;
    if (modbus_) modbus_->show(imageOf(publication.document, publication.alarmLatched, results_));
    if (mqtt_) mqtt_->publish(publication.document);
}

std::optional<int> ScadaInterfaces::modbusPort() const {
    return modbus_ ? std::optional<int>(modbus_->port()) : std::nullopt;
}

std::string ScadaInterfaces::summary() const {
    std::string text;
    if (modbus_) text += "modbus " + modbusHost_ + ":" + std::to_string(modbus_->port());
    if (mqtt_) text += (text.empty() ? "" : ", ") + std::string("mqtt ") + broker_;
    return text;
}

}  // namespace icewatch::daemon::scada
