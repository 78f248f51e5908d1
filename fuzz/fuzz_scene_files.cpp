// A scene directory (core/volume/scene_files.cpp): the input is calibration.yaml, roi.json and
// before.png (after.png is the same) separated by lines "--8<--". Any content loads or gives an
// Error with exit status 65 or 66.
#include <cstdlib>
#include <filesystem>
#include <string>

#include "core/common/error.hpp"
#include "core/volume/scene_files.hpp"
#include "fuzz/scratch_dir.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const auto& dir = icewatch::fuzz::scratchDir();
    const std::string input(reinterpret_cast<const char*>(data), size);
    const std::string cut = "\n--8<--\n";
    const char* names[] = {"calibration.yaml", "roi.json", "before.png"};
    std::size_t start = 0;
    for (const char* name : names) {
        const std::size_t end = std::min(input.find(cut, start), input.size());
        const std::string part = start <= input.size() ? input.substr(start, end - start) : std::string();
        if (std::string(name) == "roi.json" && part.empty()) {
            std::filesystem::remove(dir / name);  // roi.json is optional: its absence is a case too
        } else {
            icewatch::fuzz::writeFile(dir / name, part.data(), part.size());
        }
        if (std::string(name) == "before.png") icewatch::fuzz::writeFile(dir / "after.png", part.data(), part.size());
        start = end + cut.size();
    }
    try {
        icewatch::volume::loadSceneDirectory(dir);
    } catch (const icewatch::Error& e) {
        if (e.code() != icewatch::kExitDataErr && e.code() != icewatch::kExitNoInput) std::abort();
    }
    return 0;
}
