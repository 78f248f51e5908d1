#pragma once

#include <stdexcept>
#include <string>

#include "core/common/exit_codes.hpp"

namespace icewatch {

// An error meant for a person and a supervisor: the message names what is wrong (file, key,
// argument, frame) and the exit code says what kind of failure it is. Thrown for configuration and
// API misuse; device and I/O failures on hot paths are return values instead.
class Error : public std::runtime_error {
public:
    Error(ExitCode code, const std::string& message) : std::runtime_error(message), code_(code) {}
    ExitCode code() const noexcept { return code_; }

private:
    ExitCode code_;
};

// Invalid arguments or inputs of a core function (empty image, sizes differ, ...).
class InvalidInput : public Error {
public:
    explicit InvalidInput(const std::string& message) : Error(kExitDataErr, message) {}
};

}  // namespace icewatch
