#pragma once

#include <chrono>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "core/config/scada_config.hpp"
#include "drivers/log/log.hpp"

struct mosquitto;

namespace icewatch::daemon::scada {

// Publishes results to an MQTT broker (libmosquitto), all retained:
//   <prefix>/latest  the latest.json document
//   <prefix>/alarm   the alarm level alone: none, warning, alarm or fault
//   <prefix>/status  online once connected; offline at a clean stop and, as the last will, when
//                    the connection dies
// One thread of its own owns the client: it connects, runs libmosquitto's network loop, and when
// the broker is away reconnects with a back-off from 1 s doubling to reconnect_max_s, logging
// each kind of failure once. The service loop only hands over documents; whatever arrived while
// the broker was away is not replayed, the latest one is published when the connection returns.
class MqttPublisher {
public:
    // Reads password_file and checks ca_file at once: a missing one is Error(kExitConfig).
    // hostname fills the default client id and topic prefix.
    MqttPublisher(const config::MqttConfig& config, const std::string& hostname);
    // Publishes offline and disconnects (at most a couple of seconds), then joins.
    ~MqttPublisher();
    MqttPublisher(const MqttPublisher&) = delete;
    MqttPublisher& operator=(const MqttPublisher&) = delete;

    // Never waits on the broker.
    void publish(const nlohmann::json& document);
    const std::string& topicPrefix() const { return prefix_; }

private:
    void run();
    bool connect();
    void publishPending();
    void publishOne(const std::string& topic, const std::string& payload);
    void failed(const std::string& what);
    void backOff();
    void finish();
    static void onConnect(mosquitto* client, void* self, int code);
    static void onDisconnect(mosquitto* client, void* self, int code);

    config::MqttConfig config_;
    config::BrokerAddress broker_;
    std::string prefix_;
    std::unique_ptr<mosquitto, void (*)(mosquitto*)> client_;

    // The MQTT thread's own state.
    bool connected_ = false;
    std::chrono::seconds backoff_{1};
    log::StateLog connection_;  // "connected" or the failure: each logged once as it changes
    std::string refusal_;  // the broker's reason for refusing the last CONNECT

    std::mutex mutex_;
    std::condition_variable wake_;
    bool stopping_ = false;                   // guarded by mutex_
    std::optional<nlohmann::json> document_;  // guarded by mutex_: the newest result
    bool dirty_ = false;                      // guarded by mutex_: not yet published on this connection
    std::thread thread_;
};

}  // namespace icewatch::daemon::scada
