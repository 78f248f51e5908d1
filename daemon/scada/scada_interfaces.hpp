#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "core/config/scada_config.hpp"
#include "daemon/scada/loop_heartbeat.hpp"
#include "daemon/scada/modbus_server.hpp"
#include "daemon/scada/mqtt_publisher.hpp"
#include "daemon/scada/publication.hpp"

namespace icewatch::daemon {
class Daemon;
}

namespace icewatch::daemon::scada {

// The SCADA interfaces the configuration turns on, fed with every publication of the daemon:
// the Modbus server (its coils ask the daemon to measure or reset, its stale bit is the daemon's)
// and the MQTT publisher.
class ScadaInterfaces : public PublicationSink {
public:
    // heartbeat: the loop's pulse for the Modbus heartbeat register (it must be the notifier the
    // daemon was given); null counts nothing. Throws Error when a server cannot start.
    ScadaInterfaces(const config::ScadaConfig& config, Daemon& daemon, const LoopHeartbeat* heartbeat,
                    const ModbusLimits& modbusLimits = {});

    void published(const Publication& publication) override;

    std::optional<int> modbusPort() const;
    // "modbus 127.0.0.1:1502, mqtt mqtt://broker:1883" for the service's status line; "" when off.
    std::string summary() const;

private:
    std::uint32_t results_ = 0;  // loop thread only
    std::string modbusHost_;
    std::unique_ptr<ModbusServer> modbus_;
    std::unique_ptr<MqttPublisher> mqtt_;
    std::string broker_;
};

// This machine's name, for the default MQTT client id and topic prefix.
std::string hostName();

}  // namespace icewatch::daemon::scada
