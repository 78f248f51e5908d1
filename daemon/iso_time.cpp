// ISO 8601 in UTC for results, history queries and the CLI. Parsing is strict: a malformed
// ?since= must be a 400, not a silently different query.
#include "daemon/iso_time.hpp"

#include <cstdio>
#include <ctime>
#include <regex>

namespace icewatch::daemon {

std::string formatIsoUtc(std::chrono::system_clock::time_point time) {
    const std::time_t t = std::chrono::system_clock::to_time_t(
        std::chrono::floor<std::chrono::seconds>(time));
    std::tm tm{};
    gmtime_r(&t, &tm);
    char text[32];
    std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", &tm);
    return text;
}

std::optional<std::chrono::system_clock::time_point> parseIsoUtc(std::string_view text) {
    static const std::regex kPattern(
        R"(^(\d{4})-(\d{2})-(\d{2})(?:[T ](\d{2}):(\d{2})(?::(\d{2})(?:\.(\d{1,9}))?)?(Z|[+-]\d{2}:\d{2})?)?$)");
    std::cmatch m;
    if (text.size() > 64 || !std::regex_match(text.begin(), text.end(), m, kPattern)) {
        return std::nullopt;
    }
    auto number = [&](int i) { return m[i].matched ? std::stoi(m[i].str()) : 0; };
    std::tm tm{};
    tm.tm_year = number(1) - 1900;
    tm.tm_mon = number(2) - 1;
    tm.tm_mday = number(3);
    tm.tm_hour = number(4);
    tm.tm_min = number(5);
    tm.tm_sec = number(6);
    if (tm.tm_mon > 11 || tm.tm_mday < 1 || tm.tm_hour > 23 || tm.tm_min > 59 || tm.tm_sec > 60) {
        return std::nullopt;
    }
    std::tm normalised = tm;
    const std::time_t t = timegm(&normalised);
    if (normalised.tm_mday != tm.tm_mday || normalised.tm_mon != tm.tm_mon) {
        return std::nullopt;  // 2026-02-30 and the like
    }
    auto result = std::chrono::system_clock::from_time_t(t);
    if (m[7].matched) {
        std::string fraction = m[7].str();
        fraction.resize(9, '0');
        result += std::chrono::duration_cast<std::chrono::system_clock::duration>(std::chrono::nanoseconds(std::stoll(fraction)));
    }
    if (m[8].matched && m[8].str() != "Z") {
        const std::string offset = m[8].str();
        const int hours = std::stoi(offset.substr(1, 2));
        const int minutes = std::stoi(offset.substr(4, 2));
        if (hours > 23 || minutes > 59) {
            return std::nullopt;
        }
        const auto shift = std::chrono::hours(hours) + std::chrono::minutes(minutes);
        result += offset[0] == '+' ? -shift : shift;
    }
    return result;
}

}  // namespace icewatch::daemon
