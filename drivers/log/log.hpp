#pragma once

#include <memory>
#include <mutex>
#include <string>

#include <spdlog/spdlog.h>

namespace icewatch::log {

// Sets up logging to stderr, where journald collects it. Under systemd (JOURNAL_STREAM set) lines
// carry no timestamp of their own; journald adds one. level: trace, debug, info, warn, error.
void setup(const std::string& level);
void setLevel(const std::string& level);

// A logger tagged with its subsystem ("v4l2", "gpio", "daemon", ...): every line shows the tag.
std::shared_ptr<spdlog::logger> get(const std::string& subsystem);

// Logs a repeating condition once per change of state: a camera that stays absent for an hour is
// one line when it goes and one when it returns, not one per retry.
class StateLog {
public:
    explicit StateLog(std::shared_ptr<spdlog::logger> logger) : logger_(std::move(logger)) {}

    // Logs message at level when state differs from the last one reported; returns whether it did.
    bool report(const std::string& state, spdlog::level::level_enum level, const std::string& message);
    const std::string& state() const { return state_; }

private:
    std::shared_ptr<spdlog::logger> logger_;
    std::mutex mutex_;
    std::string state_;
};

}  // namespace icewatch::log
