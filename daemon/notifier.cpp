// sd_notify for Type=notify and WatchdogSec=. WATCHDOG=1 is only sent by the service loop when it
// has come round (or a cycle has finished a frame, or the chain a stage), so a hung cycle or a dead
// loop stops the pings and systemd restarts the service. Before READY=1 the chain's stages extend
// the start timeout instead (EXTEND_TIMEOUT_USEC).
#include "daemon/notifier.hpp"

#include <systemd/sd-daemon.h>

namespace icewatch::daemon {

SystemdNotifier::SystemdNotifier() {
    uint64_t usec = 0;
    if (sd_watchdog_enabled(0, &usec) > 0 && usec > 0) {
        watchdog_ = std::chrono::microseconds(usec);
    }
}

void SystemdNotifier::notify(const std::string& message) {
    sd_notify(0, message.c_str());
}

}  // namespace icewatch::daemon
