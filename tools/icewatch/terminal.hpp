#pragma once

#include <chrono>
#include <filesystem>
#include <string>

#include <CLI/CLI.hpp>

namespace icewatch::cli {

// A progress line on stderr for long commands ("synth: rendering 3840x1080 (12 s)"), redrawn in
// place, and only when stderr is a terminal: a supervisor, a pipe or a log file sees nothing.
// The line is cleared when the object goes, so the command's own output starts on a clean line.
class Progress {
public:
    explicit Progress(std::string command);
    ~Progress();
    Progress(const Progress&) = delete;
    Progress& operator=(const Progress&) = delete;

    void show(const std::string& what);
    void show(const std::string& what, std::size_t done, std::size_t total);
    // Clears the line (before the command prints its result).
    void done();
    bool active() const { return active_; }

private:
    std::string command_;
    bool active_ = false;
    bool shown_ = false;
    std::chrono::steady_clock::time_point start_;
};

// Registers --force on a command that writes into an output directory.
void addForceFlag(CLI::App& command, bool& force);

// An output directory that exists and holds anything is refused unless `force` (another command's
// results, a recording, a person's files): Error(kExitCantCreate) naming it and --force.
void checkOutputDirectory(const std::filesystem::path& dir, bool force, const std::string& option);

}  // namespace icewatch::cli
