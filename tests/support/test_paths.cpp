#include "tests/support/test_paths.hpp"

#include <cstdlib>
#include <string>

#include <gtest/gtest.h>
#include <unistd.h>

namespace icewatch::test {

std::filesystem::path sharedData() {
    if (const char* env = std::getenv("ICEWATCH_SHARED_DATA")) {
        return env;
    }
    return ICEWATCH_SHARED_DATA_DIR;
}

std::filesystem::path sourceDir() { return ICEWATCH_SOURCE_DIR; }

std::filesystem::path binDir() { return ICEWATCH_BIN_DIR; }

std::filesystem::path freshTempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = "icewatch-test-" + std::to_string(::getpid());
    if (info != nullptr) {
        name += std::string("-") + info->test_suite_name() + "-" + info->name();
    }
    for (char& c : name) {
        if (c == '/') c = '_';
    }
    const auto dir = std::filesystem::temp_directory_path() / name;
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir;
}

}  // namespace icewatch::test
