#pragma once

// A private directory for targets whose code under test reads files, made once per process and
// reused for every input (libFuzzer runs millions).
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace icewatch::fuzz {

inline const std::filesystem::path& scratchDir() {
    static const std::filesystem::path dir = [] {
        std::string pattern = (std::filesystem::temp_directory_path() / "icewatch-fuzz-XXXXXX").string();
        return std::filesystem::path(::mkdtemp(pattern.data()));
    }();
    return dir;
}

inline void writeFile(const std::filesystem::path& path, const char* data, std::size_t size) {
    std::ofstream(path, std::ios::binary | std::ios::trunc).write(data, static_cast<std::streamsize>(size));
}

}  // namespace icewatch::fuzz
