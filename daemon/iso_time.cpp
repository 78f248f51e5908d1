// ISO 8601 in UTC for results, history queries and the CLI. Parsing is strict: a malformed
// ?since= must be a 400, not a silently different query.
#include "daemon/iso_time.hpp"

#include <cstdio>
#include <ctime>

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

namespace {

// Reads exactly `digits` decimal digits at pos.
std::optional<int> digitsAt(std::string_view text, std::size_t pos, std::size_t digits) {
    if (pos + digits > text.size()) return std::nullopt;
    int value = 0;
    for (std::size_t i = pos; i < pos + digits; ++i) {
        if (text[i] < '0' || text[i] > '9') return std::nullopt;
        value = value * 10 + (text[i] - '0');
    }
    return value;
}

}  // namespace

std::optional<std::chrono::system_clock::time_point> parseIsoUtc(std::string_view text) {
    // YYYY-MM-DD[(T| )HH:MM[:SS[.f{1,9}]][Z|(+|-)HH:MM]]
    const auto year = digitsAt(text, 0, 4), month = digitsAt(text, 5, 2), day = digitsAt(text, 8, 2);
    if (!year || !month || !day || text.size() < 10 || text[4] != '-' || text[7] != '-') {
        return std::nullopt;
    }
    std::tm tm{};
    tm.tm_year = *year - 1900;
    tm.tm_mon = *month - 1;
    tm.tm_mday = *day;
    std::size_t pos = 10;
    long long nanoseconds = 0;
    int offsetMinutes = 0;
    if (pos < text.size()) {
        const auto hour = digitsAt(text, 11, 2), minute = digitsAt(text, 14, 2);
        if ((text[pos] != 'T' && text[pos] != ' ') || !hour || !minute || text[13] != ':') {
            return std::nullopt;
        }
        tm.tm_hour = *hour;
        tm.tm_min = *minute;
        pos = 16;
        if (pos < text.size() && text[pos] == ':') {
            const auto second = digitsAt(text, 17, 2);
            if (!second) return std::nullopt;
            tm.tm_sec = *second;
            pos = 19;
            if (pos < text.size() && text[pos] == '.') {
                std::size_t digits = 0;
                ++pos;
                while (pos < text.size() && text[pos] >= '0' && text[pos] <= '9' && digits < 9) {
                    nanoseconds = nanoseconds * 10 + (text[pos] - '0');
                    ++pos;
                    ++digits;
                }
                if (digits == 0) return std::nullopt;
                for (std::size_t d = digits; d < 9; ++d) nanoseconds *= 10;
            }
        }
        if (pos < text.size() && text[pos] == 'Z') {
            ++pos;
        } else if (pos < text.size() && (text[pos] == '+' || text[pos] == '-')) {
            const auto oh = digitsAt(text, pos + 1, 2), om = digitsAt(text, pos + 4, 2);
            if (!oh || !om || pos + 3 >= text.size() || text[pos + 3] != ':' || *oh > 23 || *om > 59) {
                return std::nullopt;
            }
            offsetMinutes = (text[pos] == '+' ? 1 : -1) * (*oh * 60 + *om);
            pos += 6;
        }
        if (pos != text.size()) return std::nullopt;
    }
    if (tm.tm_mon < 0 || tm.tm_mon > 11 || tm.tm_mday < 1 || tm.tm_hour > 23 || tm.tm_min > 59 || tm.tm_sec > 60) {
        return std::nullopt;
    }
    std::tm normalised = tm;
    const std::time_t t = timegm(&normalised);
    if (normalised.tm_mday != tm.tm_mday || normalised.tm_mon != tm.tm_mon) {
        return std::nullopt;  // 2026-02-30 and the like
    }
    auto result = std::chrono::system_clock::from_time_t(t);
    result += std::chrono::duration_cast<std::chrono::system_clock::duration>(std::chrono::nanoseconds(nanoseconds));
    result -= std::chrono::minutes(offsetMinutes);
    return result;
}

}  // namespace icewatch::daemon
