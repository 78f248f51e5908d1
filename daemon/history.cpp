// Measurement history in SQLite (WAL journal: readers such as `icewatch history` never block the
// daemon's writes). Rows carry the result fields as columns so they can be queried with the
// sqlite3 shell as well; quality and timings are JSON text.
#include "daemon/history.hpp"

#include <sqlite3.h>

#include <sstream>

#include "core/common/error.hpp"
#include "daemon/cycle_result.hpp"
#include "daemon/iso_time.hpp"
#include "drivers/log/log.hpp"

namespace icewatch::daemon {

namespace {

constexpr const char* kSchema = R"(
CREATE TABLE IF NOT EXISTS results (
    id INTEGER PRIMARY KEY,
    schema INTEGER NOT NULL,
    time_unix INTEGER NOT NULL,
    time TEXT NOT NULL,
    status TEXT NOT NULL,
    reason TEXT,
    volume_mm3 REAL,
    uncertainty_mm3 REAL,
    mean_thickness_mm REAL,
    max_thickness_mm REAL,
    valid_percent REAL,
    alarm TEXT NOT NULL,
    camera TEXT NOT NULL,
    quality TEXT NOT NULL,
    timings_ms TEXT NOT NULL,
    version TEXT NOT NULL,
    config_sha256 TEXT NOT NULL
);
CREATE INDEX IF NOT EXISTS results_time ON results(time_unix);
)";

constexpr const char* kColumns =
    "schema, time, status, reason, volume_mm3, uncertainty_mm3, mean_thickness_mm, max_thickness_mm, "
    "valid_percent, alarm, camera, quality, timings_ms, version, config_sha256";

// Finalises a statement however the function is left.
struct Statement {
    sqlite3_stmt* stmt = nullptr;
    ~Statement() { sqlite3_finalize(stmt); }
};

long long unixSeconds(std::chrono::system_clock::time_point t) {
    return std::chrono::duration_cast<std::chrono::seconds>(t.time_since_epoch()).count();
}

void bindOptional(sqlite3_stmt* stmt, int index, const std::optional<double>& value) {
    if (value) {
        sqlite3_bind_double(stmt, index, *value);
    } else {
        sqlite3_bind_null(stmt, index);
    }
}

nlohmann::json columnJson(sqlite3_stmt* stmt, int index) {
    switch (sqlite3_column_type(stmt, index)) {
        case SQLITE_NULL: return nullptr;
        case SQLITE_INTEGER: return sqlite3_column_int64(stmt, index);
        case SQLITE_FLOAT: return sqlite3_column_double(stmt, index);
        default: return std::string(reinterpret_cast<const char*>(sqlite3_column_text(stmt, index)));
    }
}

std::string csvField(const nlohmann::json& value) {
    if (value.is_null()) return "";
    std::string text = value.is_string() ? value.get<std::string>() : value.dump();
    if (text.find_first_of(",\"\n\r") == std::string::npos) return text;
    std::string quoted = "\"";
    for (char c : text) {
        quoted += c;
        if (c == '"') quoted += '"';
    }
    return quoted + "\"";
}

const std::vector<std::string> kCsvColumns{"time",          "status",           "reason",           "volume_mm3",
                                           "uncertainty_mm3", "mean_thickness_mm", "max_thickness_mm", "valid_percent",
                                           "alarm",         "camera",           "quality",          "version",
                                           "config_sha256"};

}  // namespace

History::History(const std::filesystem::path& file, Mode mode) : file_(file) {
    const int flags = mode == Mode::ReadOnly ? SQLITE_OPEN_READONLY : SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE;
    if (sqlite3_open_v2(file.c_str(), &db_, flags | SQLITE_OPEN_FULLMUTEX, nullptr) != SQLITE_OK) {
        const std::string why = db_ ? sqlite3_errmsg(db_) : "out of memory";
        sqlite3_close(db_);
        db_ = nullptr;
        throw Error(mode == Mode::ReadOnly ? kExitNoInput : kExitCantCreate,
                    file.string() + ": cannot open the history database: " + why);
    }
    sqlite3_busy_timeout(db_, 5000);
    if (mode == Mode::ReadWrite) {
        char* message = nullptr;
        const std::string setup = std::string("PRAGMA journal_mode=WAL; PRAGMA synchronous=NORMAL;") + kSchema;
        if (sqlite3_exec(db_, setup.c_str(), nullptr, nullptr, &message) != SQLITE_OK) {
            const std::string why = message ? message : "unknown error";
            sqlite3_free(message);
            sqlite3_close(db_);
            db_ = nullptr;
            throw Error(kExitCantCreate, file.string() + ": cannot set up the history database: " + why);
        }
    }
}

History::~History() {
    sqlite3_close(db_);
}

bool History::append(const CycleResult& r) {
    std::lock_guard lock(mutex_);
    const nlohmann::json doc = toJson(r);
    Statement s;
    const std::string sql = std::string("INSERT INTO results (time_unix, ") + kColumns +
                            ") VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12, ?13, ?14, ?15, ?16)";
    if (sqlite3_prepare_v2(db_, sql.c_str(), -1, &s.stmt, nullptr) != SQLITE_OK) {
        log::get("history")->error("{}: cannot prepare insert: {}", file_.string(), sqlite3_errmsg(db_));
        return false;
    }
    const std::string time = doc["time"].get<std::string>();
    const std::string quality = doc["quality"].dump();
    const std::string timings = doc["timings_ms"].dump();
    sqlite3_bind_int64(s.stmt, 1, unixSeconds(r.time));
    sqlite3_bind_int(s.stmt, 2, kResultSchema);
    sqlite3_bind_text(s.stmt, 3, time.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(s.stmt, 4, toString(r.status), -1, SQLITE_STATIC);
    if (r.reason.empty()) {
        sqlite3_bind_null(s.stmt, 5);
    } else {
        sqlite3_bind_text(s.stmt, 5, r.reason.c_str(), -1, SQLITE_TRANSIENT);
    }
    bindOptional(s.stmt, 6, r.volumeMm3);
    bindOptional(s.stmt, 7, r.uncertaintyMm3);
    bindOptional(s.stmt, 8, r.meanThicknessMm);
    bindOptional(s.stmt, 9, r.maxThicknessMm);
    bindOptional(s.stmt, 10, r.validPercent);
    sqlite3_bind_text(s.stmt, 11, alarm::toString(r.alarm), -1, SQLITE_STATIC);
    sqlite3_bind_text(s.stmt, 12, toString(r.camera), -1, SQLITE_STATIC);
    sqlite3_bind_text(s.stmt, 13, quality.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(s.stmt, 14, timings.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(s.stmt, 15, r.version.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(s.stmt, 16, r.configSha256.c_str(), -1, SQLITE_TRANSIENT);
    if (sqlite3_step(s.stmt) != SQLITE_DONE) {
        log::get("history")->error("{}: cannot insert a row: {}", file_.string(), sqlite3_errmsg(db_));
        return false;
    }
    return true;
}

int History::pruneOlderThan(std::chrono::system_clock::time_point cutoff) {
    std::lock_guard lock(mutex_);
    Statement s;
    if (sqlite3_prepare_v2(db_, "DELETE FROM results WHERE time_unix < ?1", -1, &s.stmt, nullptr) != SQLITE_OK) {
        return -1;
    }
    sqlite3_bind_int64(s.stmt, 1, unixSeconds(cutoff));
    if (sqlite3_step(s.stmt) != SQLITE_DONE) {
        log::get("history")->error("{}: cannot prune: {}", file_.string(), sqlite3_errmsg(db_));
        return -1;
    }
    return sqlite3_changes(db_);
}

std::vector<nlohmann::json> History::since(std::chrono::system_clock::time_point since, int limit) const {
    std::lock_guard lock(mutex_);
    std::vector<nlohmann::json> rows;
    Statement s;
    const std::string sql =
        std::string("SELECT ") + kColumns + " FROM results WHERE time_unix >= ?1 ORDER BY time_unix, id LIMIT ?2";
    if (sqlite3_prepare_v2(db_, sql.c_str(), -1, &s.stmt, nullptr) != SQLITE_OK) {
        throw Error(kExitIoErr, file_.string() + ": cannot query the history: " + sqlite3_errmsg(db_));
    }
    sqlite3_bind_int64(s.stmt, 1, unixSeconds(since));
    sqlite3_bind_int(s.stmt, 2, limit);
    static const char* kNames[] = {"schema", "time",          "status",           "reason",           "volume_mm3",
                                   "uncertainty_mm3", "mean_thickness_mm", "max_thickness_mm", "valid_percent",
                                   "alarm",  "camera",        "quality",          "timings_ms",       "version",
                                   "config_sha256"};
    int rc = SQLITE_ROW;
    while ((rc = sqlite3_step(s.stmt)) == SQLITE_ROW) {
        nlohmann::json row = nlohmann::json::object();
        for (int i = 0; i < 15; ++i) {
            row[kNames[i]] = columnJson(s.stmt, i);
        }
        for (const char* nested : {"quality", "timings_ms"}) {
            row[nested] = nlohmann::json::parse(row[nested].get<std::string>(), nullptr, false);
        }
        rows.push_back(std::move(row));
    }
    if (rc != SQLITE_DONE) {
        throw Error(kExitIoErr, file_.string() + ": cannot read the history: " + sqlite3_errmsg(db_));
    }
    return rows;
}

std::string historyCsvHeader() {
    std::string line;
    for (const auto& c : kCsvColumns) line += (line.empty() ? "" : ",") + c;
    return line;
}

std::string historyCsvLine(const nlohmann::json& row) {
    std::string line;
    bool first = true;
    for (const auto& c : kCsvColumns) {
        nlohmann::json value = row.contains(c) ? row[c] : nlohmann::json(nullptr);
        if (c == "quality" && value.is_object() && value.contains("flags")) {
            // One cell: the flags as "flag: reason; ...".
            std::string text;
            for (const auto& f : value["flags"]) {
                text += (text.empty() ? "" : "; ") + f.value("flag", "") + ": " + f.value("reason", "");
            }
            value = text;
        }
        line += (first ? "" : ",") + csvField(value);
        first = false;
    }
    return line;
}

}  // namespace icewatch::daemon
