// Baseline persistence. The images are kept lossless (PNG) because the volume is the difference
// against them; JPEG artefacts would show up as ice. An averaged capture (float grey) is kept as
// 16-bit grey in 1/256 grey levels, so its fraction survives: rounding it to 8 bits would throw
// away what the averaging gained.
#include "daemon/baseline_store.hpp"

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

bool writePng(const std::filesystem::path& path, const cv::Mat& image) {
    std::vector<uchar> bytes;
    cv::Mat stored = image;
    if (image.depth() == CV_32F) image.convertTo(stored, CV_16U, kFloatScale);
    if (!cv::imencode(".png", stored, bytes)) {
        return false;
    }
    return writeFileAtomically(path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
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
    const nlohmann::json doc{{"time", formatIsoUtc(record.time)},
                             {"calibration_sha256", record.calibrationSha256},
                             {"left", leftName},
                             {"right", rightName},
                             {"eye_width", record.pair.left.cols},
                             {"eye_height", record.pair.left.rows}};
    std::string previousLeft, previousRight;
    if (std::ifstream in(dir / "baseline.json"); in) {
        const auto old = nlohmann::json::parse(in, nullptr, false);
        if (old.is_object()) {
            previousLeft = old.value("left", "");
            previousRight = old.value("right", "");
        }
    }
    if (!writeFileAtomically(dir / "baseline.json", doc.dump(2) + "\n")) {
        error = "cannot write " + (dir / "baseline.json").string();
        return false;
    }
    for (const auto& old : {previousLeft, previousRight}) {
        if (!old.empty() && old != leftName && old != rightName) std::filesystem::remove(dir / old, ec);
    }
    return true;
}

std::optional<BaselineRecord> loadBaseline(const std::filesystem::path& stateDir, std::string& error) {
    const auto dir = stateDir / "baseline";
    std::ifstream in(dir / "baseline.json");
    if (!in) {
        error = "no baseline in " + dir.string();
        return std::nullopt;
    }
    const auto doc = nlohmann::json::parse(in, nullptr, false);
    if (!doc.is_object() || !doc.contains("time") || !doc["time"].is_string() || !doc.contains("left") ||
        !doc["left"].is_string() || !doc.contains("right") || !doc["right"].is_string() ||
        !doc.contains("calibration_sha256") || !doc["calibration_sha256"].is_string()) {
        error = (dir / "baseline.json").string() + ": not a baseline record";
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
    return record;
}

}  // namespace icewatch::daemon
