// See loop_heartbeat.hpp: the heartbeat register rides on the loop's watchdog pings, so it stops
// exactly when the loop stops making progress (a hung cycle, a dead loop), not when some helper
// thread that could outlive the loop stops.
#include "daemon/scada/loop_heartbeat.hpp"

#include <algorithm>

namespace icewatch::daemon::scada {

LoopHeartbeat::LoopHeartbeat(Notifier& inner, std::optional<std::chrono::milliseconds> allowedGap)
    : inner_(inner),
      allowedGap_(allowedGap ? std::chrono::steady_clock::duration(*allowedGap)
                  : inner.watchdogInterval() ? std::chrono::steady_clock::duration(*inner.watchdogInterval())
                                             : std::chrono::steady_clock::duration(kDefaultAllowedGap)) {}

void LoopHeartbeat::notify(const std::string& message) {
    if (message == "WATCHDOG=1") {
        lastPing_ = std::chrono::steady_clock::now().time_since_epoch().count();
        pinged_ = true;
        if (!inner_.watchdogInterval()) return;
    } else if (message.rfind("STOPPING=1", 0) == 0) {
        stopping_ = true;
    }
    inner_.notify(message);
}

std::optional<std::chrono::microseconds> LoopHeartbeat::watchdogInterval() const {
    const std::chrono::microseconds ours = kPingInterval * 2;
    const auto theirs = inner_.watchdogInterval();
    return theirs ? std::min(*theirs, ours) : ours;
}

bool LoopHeartbeat::alive(std::chrono::steady_clock::time_point now) const {
    if (!pinged_ || stopping_) return false;
    const std::chrono::steady_clock::time_point last{std::chrono::steady_clock::duration(lastPing_.load())};
    return now - last <= allowedGap_;
}

}  // namespace icewatch::daemon::scada
