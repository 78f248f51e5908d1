#pragma once

#include <atomic>
#include <chrono>
#include <optional>
#include <string>

#include "daemon/notifier.hpp"

namespace icewatch::daemon::scada {

// The service loop's pulse, for the Modbus heartbeat register. It sits in front of the service
// manager's notifier and uses the daemon's own watchdog protocol: it asks the loop for WATCHDOG=1
// at least every second (the loop pings at half the interval it is given, and after every frame
// of a cycle) and remembers when the last ping came. A loop that stops pinging for longer than the
// allowed gap is not alive, which is the judgement systemd makes with WatchdogSec=.
class LoopHeartbeat : public Notifier {
public:
    // allowedGap: how long the loop may go without a ping; by default the service manager's
    // watchdog interval when it has one, else kDefaultAllowedGap.
    explicit LoopHeartbeat(Notifier& inner, std::optional<std::chrono::milliseconds> allowedGap = std::nullopt);

    // Forwards everything; WATCHDOG=1 only when the service manager asked for it.
    void notify(const std::string& message) override;
    // At most kPingInterval * 2, so the loop pings at least once a kPingInterval.
    std::optional<std::chrono::microseconds> watchdogInterval() const override;

    // A ping came within the allowed gap before now, and the loop has not said STOPPING=1.
    bool alive(std::chrono::steady_clock::time_point now) const;

    static constexpr std::chrono::seconds kPingInterval{1};
    static constexpr std::chrono::seconds kDefaultAllowedGap{120};  // the unit's WatchdogSec=

private:
    Notifier& inner_;
    std::chrono::steady_clock::duration allowedGap_;
    std::atomic<std::chrono::steady_clock::rep> lastPing_{0};
    std::atomic<bool> pinged_{false};
    std::atomic<bool> stopping_{false};
};

}  // namespace icewatch::daemon::scada
