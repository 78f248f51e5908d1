#pragma once

#include <chrono>
#include <filesystem>
#include <mutex>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

struct sqlite3;

namespace icewatch::daemon {

struct CycleResult;

// One row per measurement cycle in SQLite, with the fields of latest.json (schema, time, status,
// reason, volume_mm3, uncertainty_mm3, mean_thickness_mm, max_thickness_mm, valid_percent, alarm,
// camera, quality, timings_ms, version, config_sha256). Safe to use from several threads.
class History {
public:
    enum class Mode { ReadWrite, ReadOnly };
    // Opens (creating it in ReadWrite mode) the database. Throws Error naming the file:
    // kExitCantCreate when it cannot be created, kExitNoInput when a ReadOnly file is missing.
    explicit History(const std::filesystem::path& file, Mode mode = Mode::ReadWrite);
    ~History();
    History(const History&) = delete;
    History& operator=(const History&) = delete;

    // false on an I/O error (logged); the caller carries on: latest.json is the primary output.
    bool append(const CycleResult& result);
    // Deletes rows older than cutoff; returns how many, -1 on error.
    int pruneOlderThan(std::chrono::system_clock::time_point cutoff);
    // Rows at or after since, oldest first, at most limit, each as the result document.
    std::vector<nlohmann::json> since(std::chrono::system_clock::time_point since, int limit) const;

    const std::filesystem::path& file() const { return file_; }

private:
    std::filesystem::path file_;
    sqlite3* db_ = nullptr;
    mutable std::mutex mutex_;
};

// The columns of one row in CSV, RFC 4180 quoting; the header line for them.
std::string historyCsvHeader();
std::string historyCsvLine(const nlohmann::json& row);

}  // namespace icewatch::daemon
