#pragma once

#include <filesystem>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "drivers/gpio/output_line.hpp"

namespace icewatch::gpio {

struct LineTransition {
    std::string line;  // "alarm" or "healthy"
    bool energised = false;

    bool operator==(const LineTransition&) const = default;
};

// Every transition of the fake lines, in order; shared by the lines of one daemon. With a file,
// each transition is also appended to it as "LINE 0|1\n" so a test outside the process reads them.
class TransitionLog {
public:
    TransitionLog() = default;
    explicit TransitionLog(std::filesystem::path file) : file_(std::move(file)) {}

    void record(const std::string& line, bool energised);
    std::vector<LineTransition> transitions() const;

private:
    mutable std::mutex mutex_;
    std::vector<LineTransition> transitions_;
    std::filesystem::path file_;
};

// Reads what a TransitionLog wrote to its file (tests).
std::vector<LineTransition> readTransitionFile(const std::filesystem::path& file);

// A line without hardware (tests, desk PCs): records each change of state.
class FakeOutputLine : public OutputLine {
public:
    FakeOutputLine(std::string name, std::shared_ptr<TransitionLog> log) : name_(std::move(name)), log_(std::move(log)) {}

    bool set(bool energised) override;
    bool energised() const override { return energised_; }

private:
    std::string name_;
    std::shared_ptr<TransitionLog> log_;
    bool energised_ = false;
};

}  // namespace icewatch::gpio
