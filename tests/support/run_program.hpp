#pragma once

#include <string>
#include <vector>

namespace icewatch::test {

struct ProgramResult {
    int status = -1;  // exit status, or 128 + signal
    std::string out;  // stdout
    std::string err;  // stderr
};

// Runs a program (path + arguments, no shell) to completion and captures both streams.
ProgramResult runProgram(const std::vector<std::string>& argv);

}  // namespace icewatch::test
