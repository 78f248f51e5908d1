// Baseline persistence. The images are kept lossless (PNG) because the volume is the difference
// against them; JPEG artefacts would show up as ice. An averaged capture (float grey) is kept as
// 16-bit grey in 1/256 grey levels, so its fraction survives: rounding it to 8 bits would throw
// away what the averaging gained. The noise draw is signed: 16-bit too, offset by half the range.
#include "daemon/baseline_store.hpp"

#include <algorithm>
#include <fstream>
#include <iterator>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "daemon/atomic_file.hpp"
#include "daemon/iso_time.hpp"

namespace icewatch::daemon {

namespace {
constexpr double kFloatScale = 256.0;
constexpr double kNoiseOffset = 32768.0;  // grey level 0 of the noise draw; it spans ±128
constexpr const char* kCurrent = "baseline.json";
constexpr const char* kPrevious = "baseline.previous.json";

// A record document, or null when the file is missing, not JSON, or of another shape.
nlohmann::json readRecord(const std::filesystem::path& file) {
    std::ifstream in(file);
    if (!in) return nullptr;
    auto doc = nlohmann::json::parse(in, nullptr, false);
    for (const char* key : {"time", "left", "right", "calibration_sha256"}) {
        if (!doc.is_object() || !doc.contains(key) || !doc[key].is_string()) return nullptr;
    }
    return doc;
}

std::string text(const nlohmann::json& record, const char* key) {
    return record.is_object() && record.contains(key) && record[key].is_string() ? record[key].get<std::string>()
                                                                               : std::string();
}

bool writePng(const std::filesystem::path& path, const cv::Mat& image) {
    std::vector<uchar> bytes;
    cv::Mat stored = image;
    if (image.depth() == CV_32F) image.convertTo(stored, CV_16U, kFloatScale);
    if (!cv::imencode(".png", stored, bytes)) {
        return false;
    }
    return writeFileAtomically(path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}
bool writeNoisePng(const std::filesystem::path& path, const cv::Mat& noise) {
    cv::Mat stored;
    noise.convertTo(stored, CV_16U, kFloatScale, kNoiseOffset);
    std::vector<uchar> bytes;
    return cv::imencode(".png", stored, bytes) &&
           writeFileAtomically(path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}
cv::Mat readNoisePng(const std::filesystem::path& path) {
    const cv::Mat stored = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
    if (stored.depth() != CV_16U || stored.channels() != 1) return {};
    cv::Mat noise;
    stored.convertTo(noise, CV_32F, 1.0 / kFloatScale, -kNoiseOffset / kFloatScale);
    return noise;
}
cv::Mat readPng(const std::filesystem::path& path) {
    cv::Mat image = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
    if (image.depth() == CV_16U && image.channels() == 1) {
        cv::Mat grey;
        image.convertTo(grey, CV_32F, 1.0 / kFloatScale);
        return grey;
    }
    if (image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3)) return {};
    return image;
}
}  // namespace

bool saveBaseline(const std::filesystem::path& stateDir, const BaselineRecord& record, std::string& error) {
    const auto dir = stateDir / "baseline";
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    const auto stamp = std::to_string(std::chrono::duration_cast<std::chrono::seconds>(record.time.time_since_epoch()).count());
    const std::string leftName = "left-" + stamp + ".png";
    const std::string rightName = "right-" + stamp + ".png";
    if (!writePng(dir / leftName, record.pair.left) || !writePng(dir / rightName, record.pair.right)) {
        error = "cannot write the baseline images in " + dir.string();
        return false;
    }
    nlohmann::json doc{{"time", formatIsoUtc(record.time)},
                       {"calibration_sha256", record.calibrationSha256},
                       {"left", leftName},
                       {"right", rightName},
                       {"requested_by", record.requestedBy},
                       {"eye_width", record.pair.left.cols},
                       {"eye_height", record.pair.left.rows}};
    if (!record.noise.left.empty() && !record.noise.right.empty()) {
        const std::string noiseLeft = "noise-left-" + stamp + ".png", noiseRight = "noise-right-" + stamp + ".png";
        if (!writeNoisePng(dir / noiseLeft, record.noise.left) || !writeNoisePng(dir / noiseRight, record.noise.right)) {
            error = "cannot write the baseline's noise images in " + dir.string();
            return false;
        }
        doc["noise_left"] = noiseLeft;
        doc["noise_right"] = noiseRight;
    }
    const nlohmann::json current = readRecord(dir / kCurrent);
    const nlohmann::json previous = readRecord(dir / kPrevious);
    // The record being replaced becomes the previous one before the new one is in place: a crash
    // in between leaves the old reference current and also kept as previous.
    if (!current.is_null() && !writeFileAtomically(dir / kPrevious, current.dump(2) + "\n")) {
        error = "cannot write " + (dir / kPrevious).string();
        return false;
    }
    if (!writeFileAtomically(dir / kCurrent, doc.dump(2) + "\n")) {
        error = "cannot write " + (dir / kCurrent).string();
        return false;
    }
    // Images of the record that fell off the end (neither current nor previous any more).
    const auto images = [](const nlohmann::json& r) {
        return std::vector<std::string>{text(r, "left"), text(r, "right"), text(r, "noise_left"), text(r, "noise_right")};
    };
    const std::vector<std::string> kept = images(doc), alsoKept = images(current);
    for (const auto& old : images(previous)) {
        const auto in = [&old](const std::vector<std::string>& names) { return std::find(names.begin(), names.end(), old) != names.end(); };
        if (!old.empty() && !in(kept) && !in(alsoKept) && !std::filesystem::path(old).has_parent_path()) {
            std::filesystem::remove(dir / old, ec);
        }
    }
    return true;
}

bool restoreBaseline(const std::filesystem::path& stateDir, std::string& error) {
    const auto dir = stateDir / "baseline";
    const nlohmann::json current = readRecord(dir / kCurrent);
    const nlohmann::json previous = readRecord(dir / kPrevious);
    if (previous.is_null()) {
        error = "no previous baseline in " + dir.string() + " to go back to";
        return false;
    }
    if (!writeFileAtomically(dir / kCurrent, previous.dump(2) + "\n")) {
        error = "cannot write " + (dir / kCurrent).string();
        return false;
    }
    if (!current.is_null() && !writeFileAtomically(dir / kPrevious, current.dump(2) + "\n")) {
        error = "cannot write " + (dir / kPrevious).string();
        return false;
    }
    return true;
}

std::optional<BaselineRecord> loadBaseline(const std::filesystem::path& stateDir, std::string& error) {
    const auto dir = stateDir / "baseline";
    if (!std::filesystem::exists(dir / kCurrent)) {
        error = "no baseline in " + dir.string();
        return std::nullopt;
    }
    const nlohmann::json doc = readRecord(dir / kCurrent);
    if (doc.is_null()) {
        error = (dir / kCurrent).string() + ": not a baseline record (time, left, right, calibration_sha256)";
        return std::nullopt;
    }
    const auto time = parseIsoUtc(doc["time"].get<std::string>());
    if (!time) {
        error = (dir / "baseline.json").string() + ": time: not ISO 8601";
        return std::nullopt;
    }
    BaselineRecord record;
    record.time = *time;
    record.calibrationSha256 = doc["calibration_sha256"].get<std::string>();
    record.requestedBy = text(doc, "requested_by");
    // The names must stay inside the directory.
    const std::filesystem::path leftName = doc["left"].get<std::string>(), rightName = doc["right"].get<std::string>();
    if (leftName.has_parent_path() || rightName.has_parent_path()) {
        error = (dir / "baseline.json").string() + ": image names must be plain file names";
        return std::nullopt;
    }
    record.pair.left = readPng(dir / leftName);
    record.pair.right = readPng(dir / rightName);
    if (record.pair.left.empty() || record.pair.right.empty() || record.pair.left.size() != record.pair.right.size()) {
        error = dir.string() + ": the baseline images are missing or unreadable";
        return std::nullopt;
    }
    const std::string noiseLeft = text(doc, "noise_left"), noiseRight = text(doc, "noise_right");
    if (noiseLeft.empty() != noiseRight.empty() || std::filesystem::path(noiseLeft).has_parent_path() ||
        std::filesystem::path(noiseRight).has_parent_path()) {
        error = (dir / "baseline.json").string() + ": noise_left and noise_right must both be plain file names, or both absent";
        return std::nullopt;
    }
    if (!noiseLeft.empty()) {
        record.noise.left = readNoisePng(dir / noiseLeft);
        record.noise.right = readNoisePng(dir / noiseRight);
        if (record.noise.left.size() != record.pair.left.size() || record.noise.right.size() != record.pair.right.size()) {
            error = dir.string() + ": the baseline's noise images (" + noiseLeft + ", " + noiseRight +
                    ") are missing, unreadable or not the size of its images";
            return std::nullopt;
        }
    }
    return record;
}

}  // namespace icewatch::daemon
