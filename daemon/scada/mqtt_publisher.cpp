// MQTT through libmosquitto. Every call into the library happens on the publisher's own thread
// (the callbacks run inside mosquitto_loop there too), so the client needs no locking; the
// service loop only swaps the newest document in under a mutex. The thread runs the network loop
// itself rather than mosquitto_loop_start: libmosquitto's own thread gives up for good after a TLS
// or protocol error and sleeps through a stop request, while a daemon on a tower must keep trying
// and stop promptly.
#include "daemon/scada/mqtt_publisher.hpp"

#include <mosquitto.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>

#include "core/common/error.hpp"
#include "drivers/log/log.hpp"

namespace icewatch::daemon::scada {

namespace {

constexpr int kKeepaliveS = 30;   // a silently dead broker is noticed within 1.5 x this
constexpr int kLoopTimeoutMs = 100;  // how soon a handed-over document goes out
constexpr auto kFinishTimeout = std::chrono::seconds(2);

std::shared_ptr<spdlog::logger> logger() {
    return log::get("mqtt");
}

void initLibrary() {
    // Process-wide and not thread-safe; it is never undone (the process exit frees it).
    static std::once_flag once;
    std::call_once(once, [] { mosquitto_lib_init(); });
}

// libmosquitto's messages end in a full stop; ours go on after them.
std::string clause(std::string text) {
    if (!text.empty() && text.back() == '.') text.pop_back();
    return text;
}

std::string describe(int code) {
    return clause(code == MOSQ_ERR_ERRNO ? std::strerror(errno) : mosquitto_strerror(code));
}

std::string readPassword(const std::string& path) {
    std::ifstream in(path);
    std::string line;
    if (!in || !std::getline(in, line)) {
        throw Error(kExitConfig, "scada.mqtt.password_file: cannot read " + path);
    }
    if (!line.empty() && line.back() == '\r') line.pop_back();
    return line;
}

}  // namespace

MqttPublisher::MqttPublisher(const config::MqttConfig& config, const std::string& hostname)
    : config_(config), client_(nullptr, &mosquitto_destroy), connection_(logger()) {
    const auto broker = config::parseBrokerUrl(config.broker);
    if (!broker) {
        throw Error(kExitConfig, "scada.mqtt.broker: not mqtt://host[:port] or mqtts://host[:port]: \"" +
                                     config.broker + "\"");
    }
    broker_ = *broker;
    prefix_ = config.topicPrefix.empty() ? "icewatch/" + hostname : config.topicPrefix;
    const std::string clientId = config.clientId.empty() ? "icewatch-" + hostname : config.clientId;
    initLibrary();
    client_.reset(mosquitto_new(clientId.c_str(), /*clean_session=*/true, this));
    if (!client_) {
        throw Error(kExitSoftware, "mqtt: cannot create a client: " + std::string(std::strerror(errno)));
    }
    mosquitto* c = client_.get();
    mosquitto_connect_callback_set(c, &MqttPublisher::onConnect);
    mosquitto_disconnect_callback_set(c, &MqttPublisher::onDisconnect);
    if (!config.username.empty()) {
        const std::string password = config.passwordFile.empty() ? std::string() : readPassword(config.passwordFile);
        if (mosquitto_username_pw_set(c, config.username.c_str(), config.passwordFile.empty() ? nullptr : password.c_str()) !=
            MOSQ_ERR_SUCCESS) {
            throw Error(kExitConfig, "scada.mqtt.username: not accepted by libmosquitto");
        }
    }
    if (broker_.tls) {
        int rc = MOSQ_ERR_SUCCESS;
        if (config.caFile.empty()) {
            rc = mosquitto_int_option(c, MOSQ_OPT_TLS_USE_OS_CERTS, 1);
        } else if (!std::ifstream(config.caFile)) {
            throw Error(kExitConfig, "scada.mqtt.ca_file: cannot read " + config.caFile);
        } else {
            rc = mosquitto_tls_set(c, config.caFile.c_str(), nullptr, nullptr, nullptr, nullptr);
        }
        if (rc != MOSQ_ERR_SUCCESS) {
            throw Error(kExitConfig, "scada.mqtt.ca_file: TLS set-up failed: " + describe(rc));
        }
    }
    const std::string offline = "offline";
    const std::string status = prefix_ + "/status";
    if (mosquitto_will_set(c, status.c_str(), static_cast<int>(offline.size()), offline.data(), config_.qos, true) !=
        MOSQ_ERR_SUCCESS) {
        throw Error(kExitConfig, "scada.mqtt.topic_prefix: \"" + prefix_ + "\" is not a valid topic");
    }
    thread_ = std::thread([this] { run(); });
    logger()->info("publishing to {} as {} under {}/", config_.broker, clientId, prefix_);
}

MqttPublisher::~MqttPublisher() {
    {
        std::lock_guard lock(mutex_);
        stopping_ = true;
    }
    wake_.notify_all();
    if (thread_.joinable()) thread_.join();
}

void MqttPublisher::publish(const nlohmann::json& document) {
    std::lock_guard lock(mutex_);
    document_ = document;
    dirty_ = true;
}

void MqttPublisher::run() {
    bool open = false;  // a socket exists: connected, or the connect is under way
    while (true) {
        {
            std::lock_guard lock(mutex_);
            if (stopping_) break;
        }
        if (!open) {
            open = connect();
            if (!open) {
                backOff();
                continue;
            }
        }
        publishPending();
        const int rc = mosquitto_loop(client_.get(), kLoopTimeoutMs, 1);
        if (rc != MOSQ_ERR_SUCCESS) {
            open = false;
            connected_ = false;
            failed(refusal_.empty() ? describe(rc) : refusal_);
            refusal_.clear();
            backOff();
        }
    }
    finish();
}

bool MqttPublisher::connect() {
    const int rc = mosquitto_connect_async(client_.get(), broker_.host.c_str(), broker_.port, kKeepaliveS);
    if (rc != MOSQ_ERR_SUCCESS) {
        failed(describe(rc));
        return false;
    }
    return true;
}

void MqttPublisher::publishPending() {
    if (!connected_) return;
    nlohmann::json document;
    {
        std::lock_guard lock(mutex_);
        if (!dirty_ || !document_) return;
        document = *document_;
        dirty_ = false;
    }
    publishOne(prefix_ + "/latest", document.dump());
    const auto alarm = document.find("alarm");
    publishOne(prefix_ + "/alarm", alarm != document.end() && alarm->is_string() ? alarm->get<std::string>() : "fault");
}

void MqttPublisher::publishOne(const std::string& topic, const std::string& payload) {
    const int rc = mosquitto_publish(client_.get(), nullptr, topic.c_str(), static_cast<int>(payload.size()),
                                     payload.data(), config_.qos, /*retain=*/true);
    if (rc != MOSQ_ERR_SUCCESS) {
        // The loop notices a dead connection itself; the reconnect publishes the newest again.
        logger()->debug("publishing {} failed: {}", topic, describe(rc));
    }
}

void MqttPublisher::failed(const std::string& what) {
    connection_.report(what, spdlog::level::warn,
                       "broker " + config_.broker + ": " + what + "; retrying in the background (back-off up to " +
                           std::to_string(config_.reconnectMaxS) + " s)");
}

void MqttPublisher::backOff() {
    std::unique_lock lock(mutex_);
    wake_.wait_for(lock, backoff_, [this] { return stopping_; });
    backoff_ = std::min(backoff_ * 2, std::chrono::seconds(config_.reconnectMaxS));
}

void MqttPublisher::finish() {
    if (!connected_) return;
    // A clean DISCONNECT suppresses the will, so say offline ourselves first; both go out in order.
    publishOne(prefix_ + "/status", "offline");
    mosquitto_disconnect(client_.get());
    const auto deadline = std::chrono::steady_clock::now() + kFinishTimeout;
    while (std::chrono::steady_clock::now() < deadline &&
           mosquitto_loop(client_.get(), kLoopTimeoutMs, 1) == MOSQ_ERR_SUCCESS) {
    }
    logger()->info("disconnected from {}", config_.broker);
}

void MqttPublisher::onConnect(mosquitto*, void* self, int code) {
    auto* p = static_cast<MqttPublisher*>(self);
    if (code != 0) {
        p->refusal_ = "the broker refused the connection: " + clause(mosquitto_connack_string(code));
        return;
    }
    p->connected_ = true;
    p->backoff_ = std::chrono::seconds(1);
    p->connection_.report("connected", spdlog::level::info, "connected to " + p->config_.broker);
    p->publishOne(p->prefix_ + "/status", "online");
    std::lock_guard lock(p->mutex_);
    p->dirty_ = true;  // the newest result, whatever the broker kept or lost
}

void MqttPublisher::onDisconnect(mosquitto*, void* self, int) {
    static_cast<MqttPublisher*>(self)->connected_ = false;
}

}  // namespace icewatch::daemon::scada
