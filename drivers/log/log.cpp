// The process's log sink: stderr, one line per event, tagged with the subsystem.
#include "drivers/log/log.hpp"

#include <cstdlib>

#include <spdlog/sinks/stdout_sinks.h>

namespace icewatch::log {

namespace {

std::shared_ptr<spdlog::sinks::stderr_sink_mt> sink() {
    static auto s = std::make_shared<spdlog::sinks::stderr_sink_mt>();
    return s;
}

spdlog::level::level_enum& currentLevel() {
    static spdlog::level::level_enum level = spdlog::level::info;
    return level;
}

std::string pattern() {
    // journald timestamps every line itself; a terminal wants ours.
    return std::getenv("JOURNAL_STREAM") != nullptr ? "[%n] %l: %v" : "%Y-%m-%dT%H:%M:%S.%e [%n] %l: %v";
}

}  // namespace

void setup(const std::string& level) {
    sink()->set_pattern(pattern());
    setLevel(level);
}

void setLevel(const std::string& level) {
    currentLevel() = spdlog::level::from_str(level);
    spdlog::apply_all([](const std::shared_ptr<spdlog::logger>& l) { l->set_level(currentLevel()); });
}

std::shared_ptr<spdlog::logger> get(const std::string& subsystem) {
    static std::mutex registryMutex;
    std::lock_guard<std::mutex> lock(registryMutex);
    if (auto existing = spdlog::get(subsystem)) {
        return existing;
    }
    auto logger = std::make_shared<spdlog::logger>(subsystem, sink());
    logger->set_level(currentLevel());
    logger->set_pattern(pattern());
    spdlog::register_logger(logger);
    return logger;
}

bool StateLog::report(const std::string& state, spdlog::level::level_enum level, const std::string& message) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (state == state_) {
        return false;
    }
    state_ = state;
    logger_->log(level, message);
    return true;
}

}  // namespace icewatch::log
