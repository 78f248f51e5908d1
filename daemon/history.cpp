// Measurement history in SQLite (WAL journal: readers such as `icewatch history` never block the
// daemon's writes). Rows carry the result fields as columns so they can be queried with the
// sqlite3 shell as well; quality and timings are JSON text.
#include "daemon/history.hpp"

#include <sqlite3.h>

#include <iterator>
#include <sstream>
#include <utility>

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
    config_sha256 TEXT NOT NULL,
    alarm_reason TEXT,
    last_ok TEXT,
    ice_area_mm2 REAL,
    beyond_outline_mm3 REAL,
    mean_thickness_uncertainty_mm REAL
);
CREATE INDEX IF NOT EXISTS results_time ON results(time_unix);
)";

constexpr const char* kColumns =
    "schema, time, status, reason, volume_mm3, uncertainty_mm3, mean_thickness_mm, max_thickness_mm, "
    "valid_percent, alarm, camera, quality, timings_ms, version, config_sha256, alarm_reason, last_ok, "
    "ice_area_mm2, beyond_outline_mm3, mean_thickness_uncertainty_mm";

// Columns added since the first layout, with their types, which a history written before lacks
// (its rows read null).
constexpr std::pair<const char*, const char*> kAddedColumns[] = {
    {"alarm_reason", "TEXT"},       {"last_ok", "TEXT"}, {"ice_area_mm2", "REAL"}, {"beyond_outline_mm3", "REAL"},
    {"mean_thickness_uncertainty_mm", "REAL"}};

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
                                           "uncertainty_mm3", "mean_thickness_mm", "mean_thickness_uncertainty_mm", "max_thickness_mm", "ice_area_mm2",
                                           "beyond_outline_mm3", "valid_percent", "alarm",           "camera",
                                           "quality",       "version",          "config_sha256"};

}  // namespace

History::History(const std::filesystem::path& file, Mode mode, std::chrono::system_clock::time_point now)
    : file_(file) {
    if (mode == Mode::ReadOnly) {
        std::string why;
        if (!open(SQLITE_OPEN_READONLY, why)) {
            throw Error(kExitNoInput, file.string() + ": cannot open the history database: " + why);
        }
        return;
    }
    std::string why;
    if (open(SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, why) && setUp(why)) {
        return;
    }
    // Secondary data must not stop the measurement: keep the damaged file for a person, start anew.
    moveAside(now, why);
    if (!open(SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, why) || !setUp(why)) {
        throw Error(kExitCantCreate, file.string() + ": cannot create the history database: " + why);
    }
}

bool History::open(int flags, std::string& why) {
    if (sqlite3_open_v2(file_.c_str(), &db_, flags | SQLITE_OPEN_FULLMUTEX, nullptr) != SQLITE_OK) {
        why = db_ ? sqlite3_errmsg(db_) : "out of memory";
        sqlite3_close(db_);
        db_ = nullptr;
        return false;
    }
    sqlite3_busy_timeout(db_, 5000);
    return true;
}

bool History::setUp(std::string& why) {
    char* message = nullptr;
    // quick_check reads every page: a file that is not a database or has broken pages fails here,
    // not at the first insert hours later.
    const std::string setup = std::string("PRAGMA journal_mode=WAL; PRAGMA synchronous=NORMAL;") + kSchema;
    bool ok = sqlite3_exec(db_, setup.c_str(), nullptr, nullptr, &message) == SQLITE_OK;
    for (const auto& [column, type] : kAddedColumns) {
        Statement probe;
        const std::string select = std::string("SELECT ") + column + " FROM results LIMIT 0";
        if (ok && sqlite3_prepare_v2(db_, select.c_str(), -1, &probe.stmt, nullptr) != SQLITE_OK) {
            const std::string add = std::string("ALTER TABLE results ADD COLUMN ") + column + " " + type;
            ok = sqlite3_exec(db_, add.c_str(), nullptr, nullptr, &message) == SQLITE_OK;
        }
    }
    if (ok) {
        Statement check;
        ok = sqlite3_prepare_v2(db_, "PRAGMA quick_check", -1, &check.stmt, nullptr) == SQLITE_OK &&
             sqlite3_step(check.stmt) == SQLITE_ROW &&
             std::string(reinterpret_cast<const char*>(sqlite3_column_text(check.stmt, 0))) == "ok";
        if (!ok) why = std::string("integrity check: ") + sqlite3_errmsg(db_);
    } else {
        why = message ? message : "unknown error";
    }
    sqlite3_free(message);
    if (!ok) {
        sqlite3_close(db_);
        db_ = nullptr;
    }
    return ok;
}

void History::moveAside(std::chrono::system_clock::time_point now, const std::string& why) {
    std::string stamp = formatIsoUtc(now);
    for (char& c : stamp) if (c == ':') c = '-';
    const std::filesystem::path aside = file_.string() + ".damaged-" + stamp;
    std::error_code ec;
    std::filesystem::rename(file_, aside, ec);
    for (const char* suffix : {"-wal", "-shm"}) {
        std::filesystem::rename(file_.string() + suffix, aside.string() + suffix, ec);
    }
    std::filesystem::remove(file_, ec);
    recovery_ = file_.string() + " was damaged (" + why + "): moved to " + aside.filename().string() +
                " at " + formatIsoUtc(now) + ", a new one started";
    log::get("history")->error("{}", recovery_);
}

bool History::recoverIfDamaged(int rc, std::chrono::system_clock::time_point now) {
    if (rc != SQLITE_CORRUPT && rc != SQLITE_NOTADB) return false;
    const std::string why = sqlite3_errmsg(db_);
    sqlite3_close(db_);
    db_ = nullptr;
    moveAside(now, why);
    std::string problem;
    if (!open(SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, problem) || !setUp(problem)) {
        log::get("history")->error("{}: cannot start a new history: {}", file_.string(), problem);
        return false;
    }
    return true;
}

History::~History() {
    sqlite3_close(db_);
}

bool History::append(const CycleResult& r) {
    std::lock_guard lock(mutex_);
    for (int attempt = 0; attempt < 2; ++attempt) {
        const int rc = insert(r);
        if (rc == SQLITE_DONE) return true;
        // A file damaged under the running daemon: move it aside once and write the row anew.
        if (attempt > 0 || !recoverIfDamaged(rc, r.time)) break;
    }
    return false;
}

int History::insert(const CycleResult& r) {
    if (db_ == nullptr) return SQLITE_CANTOPEN;
    const nlohmann::json doc = toJson(r);
    Statement s;
    const std::string sql = std::string("INSERT INTO results (time_unix, ") + kColumns +
                            ") VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12, ?13, ?14, ?15, ?16, ?17, "
                            "?18, ?19, ?20, ?21)";
    if (const int rc = sqlite3_prepare_v2(db_, sql.c_str(), -1, &s.stmt, nullptr); rc != SQLITE_OK) {
        log::get("history")->error("{}: cannot prepare insert: {}", file_.string(), sqlite3_errmsg(db_));
        return rc;
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
    const std::string lastOk = r.lastOk ? formatIsoUtc(*r.lastOk) : std::string();
    for (const auto& [index, text] : {std::pair<int, const std::string*>{17, &r.alarmReason}, {18, &lastOk}}) {
        if (text->empty()) {
            sqlite3_bind_null(s.stmt, index);
        } else {
            sqlite3_bind_text(s.stmt, index, text->c_str(), -1, SQLITE_TRANSIENT);
        }
    }
    bindOptional(s.stmt, 19, r.iceAreaMm2);
    bindOptional(s.stmt, 20, r.beyondOutlineMm3);
    bindOptional(s.stmt, 21, r.meanThicknessUncertaintyMm);
    const int rc = sqlite3_step(s.stmt);
    if (rc != SQLITE_DONE) {
        log::get("history")->error("{}: cannot insert a row: {}", file_.string(), sqlite3_errmsg(db_));
    }
    return rc;
}

int History::pruneOlderThan(std::chrono::system_clock::time_point cutoff) {
    std::lock_guard lock(mutex_);
    if (db_ == nullptr) return -1;
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
    if (db_ == nullptr) {
        throw Error(kExitIoErr, file_.string() + ": the history database is not open");
    }
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
                                   "config_sha256", "alarm_reason", "last_ok", "ice_area_mm2", "beyond_outline_mm3",
                                   "mean_thickness_uncertainty_mm"};
    int rc = SQLITE_ROW;
    while ((rc = sqlite3_step(s.stmt)) == SQLITE_ROW) {
        nlohmann::json row = nlohmann::json::object();
        for (int i = 0; i < static_cast<int>(std::size(kNames)); ++i) {
            row[kNames[i]] = columnJson(s.stmt, i);
        }
        for (const char* nested : {"quality", "timings_ms"}) {
            // A row edited by hand may hold anything: such a cell reads as null, never as an exception.
            row[nested] = row[nested].is_string() ? nlohmann::json::parse(row[nested].get<std::string>(), nullptr, false)
                                                  : nlohmann::json(nullptr);
            if (row[nested].is_discarded()) row[nested] = nullptr;
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
                if (!f.is_object()) continue;
                const auto field = [&f](const char* key) {
                    return f.contains(key) && f[key].is_string() ? f[key].get<std::string>() : std::string();
                };
                text += (text.empty() ? "" : "; ") + field("flag") + ": " + field("reason");
            }
            value = text;
        }
        line += (first ? "" : ",") + csvField(value);
        first = false;
    }
    return line;
}

}  // namespace icewatch::daemon
