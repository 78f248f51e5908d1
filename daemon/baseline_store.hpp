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
    std::string requestedBy;  // "cli", "http 127.0.0.1 (curl/7.88.1)": who replaced the reference
    // One draw of the averaged pair's own noise (volume::AveragedCapture::noise as the pair; empty
    // when the capture had none). Kept beside it so that a reference loaded after a restart reads
    // its texture as it did when it was captured.
    StereoPair noise;
};

// The clean-blade reference in STATE_DIR/baseline/: left.png and right.png (lossless), the noise
// draw's noise-left.png and noise-right.png when there is one, and baseline.json (time,
// calibration SHA-256, image size) written last, so an interrupted save
// leaves the previous record's json pointing at complete images of its own (the PNGs are written
// under names that carry the time). The record it replaces is kept as baseline.previous.json with
// its images, so a wrong baseline can be undone (restoreBaseline). Returns false with a reason.
bool saveBaseline(const std::filesystem::path& stateDir, const BaselineRecord& record, std::string& error);

// Swaps baseline.json and baseline.previous.json (restoring twice undoes the restore). Returns
// false with a reason when there is no previous record.
bool restoreBaseline(const std::filesystem::path& stateDir, std::string& error);

// nullopt + reason when there is none or it is unreadable (a noise draw named but unreadable, or of
// another size, too). A record without a noise draw (written before it was kept) loads without one.
std::optional<BaselineRecord> loadBaseline(const std::filesystem::path& stateDir, std::string& error);

}  // namespace icewatch::daemon
