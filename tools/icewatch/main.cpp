// icewatch: the command-line program, one binary with subcommands like git. Each subcommand lives
// in its own cmd_*.cpp; this file only dispatches and turns errors into exit statuses.
#include <malloc.h>

#include <cstdio>
#include <exception>
#include <iostream>

#include <CLI/CLI.hpp>

#include "core/common/error.hpp"
#include "drivers/log/log.hpp"
#include "tools/icewatch/command.hpp"

int main(int argc, char** argv) {
    using namespace icewatch;
    // Blocks of a megabyte or more (frames, surfaces, the matcher's volumes) from mmap and back to
    // the system when freed, as in icewatchd: with glibc's adaptive threshold the frames of the
    // burst average and the matcher's buffers, once freed, stayed resident for the whole run.
    mallopt(M_MMAP_THRESHOLD, 1 << 20);
    CLI::App app{"icewatch: camera-based ice monitor for wind-turbine blades"};
    app.require_subcommand(1);
    app.set_version_flag("--version", std::string(ICEWATCH_VERSION));
    cli::GlobalOptions global;
    app.add_flag("-v,--verbose", global.verbose, "log debug messages to stderr");

    cli::RunFunction run;
    cli::addConfigCommand(app, global, run);
    cli::addCalibrateCommand(app, global, run);
    cli::addRectifyCommand(app, global, run);
    cli::addInfoCommand(app, global, run);
    cli::addRecordCommand(app, global, run);
    cli::addAcquireCommand(app, global, run);
    cli::addSynthCommand(app, global, run);
    cli::addVolumeCommand(app, global, run);
    cli::addFloorCommand(app, global, run);
    cli::addMatchCommand(app, global, run);
    cli::addEvalCommand(app, global, run);
    cli::addBenchCommand(app, global, run);
    cli::addHistoryCommand(app, global, run);
    cli::addStatusCommand(app, global, run);
    cli::addBaselineCommand(app, global, run);

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        const int status = app.exit(e);
        return status == 0 ? 0 : kExitUsage;
    }
    log::setup(global.verbose ? "debug" : "info");
    try {
        return run ? run() : kExitUsage;
    } catch (const Error& e) {
        std::cerr << "icewatch: " << e.what() << "\n";
        return e.code();
    } catch (const std::exception& e) {
        std::cerr << "icewatch: internal error: " << e.what() << "\n";
        return kExitSoftware;
    }
}
