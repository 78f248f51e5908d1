#pragma once

#include <functional>
#include <string>

#include <CLI/CLI.hpp>

namespace icewatch::cli {

// Options every subcommand shares.
struct GlobalOptions {
    bool verbose = false;
};

// Each subcommand registers itself on the app and sets `run` to what it does; run returns the
// process exit status (core/common/exit_codes.hpp). icewatch::Error thrown from run is printed
// and turned into its exit code by main.
using RunFunction = std::function<int()>;

struct Registration {
    CLI::App* command = nullptr;
    RunFunction run;
};

// One function per subcommand file (tools/icewatch/cmd_*.cpp).
void addConfigCommand(CLI::App& app, const GlobalOptions& global, RunFunction& run);
void addCalibrateCommand(CLI::App& app, const GlobalOptions& global, RunFunction& run);
void addRectifyCommand(CLI::App& app, const GlobalOptions& global, RunFunction& run);
void addInfoCommand(CLI::App& app, const GlobalOptions& global, RunFunction& run);
void addRecordCommand(CLI::App& app, const GlobalOptions& global, RunFunction& run);
void addAcquireCommand(CLI::App& app, const GlobalOptions& global, RunFunction& run);
void addSynthCommand(CLI::App& app, const GlobalOptions& global, RunFunction& run);
void addVolumeCommand(CLI::App& app, const GlobalOptions& global, RunFunction& run);
void addFloorCommand(CLI::App& app, const GlobalOptions& global, RunFunction& run);
void addMatchCommand(CLI::App& app, const GlobalOptions& global, RunFunction& run);
void addEvalCommand(CLI::App& app, const GlobalOptions& global, RunFunction& run);
void addBenchCommand(CLI::App& app, const GlobalOptions& global, RunFunction& run);
void addHistoryCommand(CLI::App& app, const GlobalOptions& global, RunFunction& run);
void addStatusCommand(CLI::App& app, const GlobalOptions& global, RunFunction& run);
void addBaselineCommand(CLI::App& app, const GlobalOptions& global, RunFunction& run);

}  // namespace icewatch::cli
