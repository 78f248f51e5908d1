#pragma once

#include <chrono>
#include <optional>
#include <string>
#include <string_view>

namespace icewatch::daemon {

// "2026-01-31T12:00:00Z": UTC, whole seconds.
std::string formatIsoUtc(std::chrono::system_clock::time_point time);

// Accepts YYYY-MM-DD, YYYY-MM-DDTHH:MM[:SS[.fff]] with an optional Z or +HH:MM / -HH:MM offset (no
// offset = UTC). nullopt for anything else, including impossible dates.
std::optional<std::chrono::system_clock::time_point> parseIsoUtc(std::string_view text);

}  // namespace icewatch::daemon
