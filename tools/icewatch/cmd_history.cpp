// icewatch history: the measurement history from the state directory's SQLite file, as JSON lines
// or CSV. Reads without locking, so it works while icewatchd runs.
#include <iostream>

#include "core/common/error.hpp"
#include "core/config/config.hpp"
#include "daemon/history.hpp"
#include "daemon/iso_time.hpp"
#include "tools/icewatch/command.hpp"

namespace icewatch::cli {

namespace {

struct HistoryOptions {
    std::string since, format = "jsonl", config = "/etc/icewatch/icewatch.json", stateDir;
    int limit = 1000000;
};

// --state-dir, else the configuration's; on a machine without the installed configuration (a
// laptop reading a copied state directory) the default one, unless --config named a file.
std::filesystem::path historyStateDir(const HistoryOptions& o, bool configGiven) {
    if (!o.stateDir.empty()) return o.stateDir;
    if (configGiven || std::filesystem::exists(o.config)) return config::loadConfig(o.config).daemon.stateDir;
    return config::DaemonConfig{}.stateDir;
}

}  // namespace

void addHistoryCommand(CLI::App& app, const GlobalOptions& /*global*/, RunFunction& run) {
    CLI::App* cmd = app.add_subcommand("history", "print the measurement history (one row per cycle)");
    using Options = HistoryOptions;
    auto o = std::make_shared<Options>();
    cmd->add_option("--since", o->since, "ISO 8601 time, e.g. 2026-01-31 or 2026-01-31T12:00:00Z (default: 24 h ago)");
    cmd->add_option("--format", o->format, "jsonl or csv")->check(CLI::IsMember({"jsonl", "csv"}))->capture_default_str();
    CLI::Option* configOption =
        cmd->add_option("--config", o->config, "configuration naming the state directory (when it exists)")
            ->capture_default_str();
    cmd->add_option("--state-dir", o->stateDir, "state directory (overrides the configuration)");
    cmd->add_option("--limit", o->limit, "at most this many rows")->check(CLI::Range(1, 100000000));
    cmd->callback([&run, o, configOption] {
        const bool configGiven = configOption->count() > 0;
        run = [o, configGiven] {
            auto since = std::chrono::system_clock::now() - std::chrono::hours(24);
            if (!o->since.empty()) {
                const auto parsed = daemon::parseIsoUtc(o->since);
                if (!parsed) {
                    throw Error(kExitUsage, "--since: not an ISO 8601 time: " + o->since);
                }
                since = *parsed;
            }
            const std::filesystem::path stateDir = historyStateDir(*o, configGiven);
            const daemon::History history(stateDir / "history.sqlite", daemon::History::Mode::ReadOnly);
            const auto rows = history.since(since, o->limit);
            if (o->format == "csv") {
                std::cout << daemon::historyCsvHeader() << "\n";
            }
            for (const auto& row : rows) {
                std::cout << (o->format == "csv" ? daemon::historyCsvLine(row) : row.dump()) << "\n";
            }
            return kExitOk;
        };
    });
}

}  // namespace icewatch::cli
