// What the CLI shows a person at a terminal and refuses to do behind their back.
#include "tools/icewatch/terminal.hpp"

#include <unistd.h>

#include <cstdio>
#include <iostream>

#include "core/common/error.hpp"

namespace icewatch::cli {

Progress::Progress(std::string command)
    : command_(std::move(command)), active_(isatty(STDERR_FILENO) == 1), start_(std::chrono::steady_clock::now()) {}

Progress::~Progress() { done(); }

void Progress::done() {
    if (shown_) std::cerr << "\r\033[K" << std::flush;
    shown_ = false;
}

void Progress::show(const std::string& what) {
    if (!active_) return;
    const auto seconds =
        std::chrono::duration_cast<std::chrono::seconds>(std::chrono::steady_clock::now() - start_).count();
    // \033[K clears what a longer earlier line left.
    std::cerr << "\r\033[K" << command_ << ": " << what << " (" << seconds << " s)" << std::flush;
    shown_ = true;
}

void Progress::show(const std::string& what, std::size_t done, std::size_t total) {
    show(what + " " + std::to_string(done) + "/" + std::to_string(total));
}

void addForceFlag(CLI::App& command, bool& force) {
    command.add_flag("--force", force, "write into an output directory that already holds files");
}

void checkOutputDirectory(const std::filesystem::path& dir, bool force, const std::string& option) {
    std::error_code ec;
    if (force || !std::filesystem::exists(dir, ec)) return;
    if (!std::filesystem::is_directory(dir, ec)) {
        throw Error(kExitCantCreate, option + " " + dir.string() + ": exists and is not a directory");
    }
    if (!std::filesystem::is_empty(dir, ec)) {
        throw Error(kExitCantCreate, option + " " + dir.string() +
                                         ": exists and is not empty; pass --force to write into it");
    }
}

}  // namespace icewatch::cli
