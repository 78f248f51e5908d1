#pragma once

#include <filesystem>

namespace icewatch::test {

// ../shared/data (ICEWATCH_SHARED_DATA in the environment overrides the built-in path).
std::filesystem::path sharedData();
// The repository root, for config/ and the bundled recording.
std::filesystem::path sourceDir();
// build/bin, where icewatch and icewatchd are.
std::filesystem::path binDir();
// A fresh, empty directory under the system temp dir, unique to this test.
std::filesystem::path freshTempDir();

}  // namespace icewatch::test
