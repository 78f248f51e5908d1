#pragma once

#include <chrono>
#include <optional>
#include <string>

namespace icewatch::daemon {

// The service manager's side channel (sd_notify): READY=1, WATCHDOG=1, STATUS=...
class Notifier {
public:
    virtual ~Notifier() = default;
    virtual void notify(const std::string& message) = 0;
    // How often WATCHDOG=1 must come, when the watchdog is on.
    virtual std::optional<std::chrono::microseconds> watchdogInterval() const = 0;
};

// libsystemd's sd_notify; a no-op outside systemd (no NOTIFY_SOCKET).
class SystemdNotifier : public Notifier {
public:
    SystemdNotifier();
    void notify(const std::string& message) override;
    std::optional<std::chrono::microseconds> watchdogInterval() const override { return watchdog_; }

private:
    std::optional<std::chrono::microseconds> watchdog_;
};

}  // namespace icewatch::daemon
