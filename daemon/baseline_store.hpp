#pragma once

#include <chrono>
#include <filesystem>
#include <optional>
#include <string>

#include "core/common/side_by_side.hpp"

namespace icewatch::daemon {

struct BaselineRecord {
    std::chrono::system_clock::time_point time;
    std::string calibrationSha256;
    StereoPair pair;
};

// The clean-blade reference in STATE_DIR/baseline/: left.png and right.png (lossless) and
// baseline.json (time, calibration SHA-256, image size) written last, so an interrupted save
// leaves the previous record's json pointing at complete images of its own (the PNGs are written
// under names that carry the time). Returns false with a reason.
bool saveBaseline(const std::filesystem::path& stateDir, const BaselineRecord& record, std::string& error);

// nullopt + reason when there is none or it is unreadable.
std::optional<BaselineRecord> loadBaseline(const std::filesystem::path& stateDir, std::string& error);

}  // namespace icewatch::daemon
