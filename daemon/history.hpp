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
// reason, volume_mm3, uncertainty_mm3, mean_thickness_mm, max_thickness_mm, ice_area_mm2,
// beyond_outline_mm3, valid_percent, alarm, camera, quality, timings_ms, version, config_sha256).
// Safe to use from several threads.
class History {
public:
    enum class Mode { ReadWrite, ReadOnly };
    // Opens (creating it in ReadWrite mode) the database. In ReadWrite mode a damaged file (not a
    // database, failing its integrity check) is renamed history.sqlite.damaged-<now> and a new one
    // started (recovery() says so). Throws Error naming the file: kExitCantCreate when it cannot be
    // created, kExitNoInput when a ReadOnly file is missing.
    explicit History(const std::filesystem::path& file, Mode mode = Mode::ReadWrite,
                     std::chrono::system_clock::time_point now = std::chrono::system_clock::now());
    ~History();
    History(const History&) = delete;
    History& operator=(const History&) = delete;

    // false on an I/O error (logged); the caller carries on: latest.json is the primary output.
    // A file found damaged while running is moved aside like at opening and the row written anew.
    bool append(const CycleResult& result);
    // Deletes rows older than cutoff; returns how many, -1 on error.
    int pruneOlderThan(std::chrono::system_clock::time_point cutoff);
    // Rows at or after since, oldest first, at most limit, each as the result document.
    std::vector<nlohmann::json> since(std::chrono::system_clock::time_point since, int limit) const;

    const std::filesystem::path& file() const { return file_; }
    // Empty, or what was damaged, when and where it went.
    std::string recovery() const {
        std::lock_guard lock(mutex_);
        return recovery_;
    }

private:
    bool open(int flags, std::string& why);
    bool setUp(std::string& why);
    void moveAside(std::chrono::system_clock::time_point now, const std::string& why);
    bool recoverIfDamaged(int rc, std::chrono::system_clock::time_point now);
    int insert(const CycleResult& result);  // an SQLite result code, SQLITE_DONE when written

    std::filesystem::path file_;
    std::string recovery_;
    sqlite3* db_ = nullptr;
    mutable std::mutex mutex_;
};

// The columns of one row in CSV, RFC 4180 quoting; the header line for them.
std::string historyCsvHeader();
std::string historyCsvLine(const nlohmann::json& row);

}  // namespace icewatch::daemon
