// The configuration file: one JSON object with a section per subsystem. Sections are read by
// typed, range-checked readers (section.hpp); nothing outside this file knows the JSON layout.
#include "core/config/config.hpp"

#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "core/config/section.hpp"

namespace icewatch::config {

namespace {

void readLog(Section s, LogConfig& log) {
    s.readChoice("level", log.level, {"trace", "debug", "info", "warn", "error"});
    s.finish();
}

void readCamera(Section s, CameraConfig& camera) {
    s.read("device", camera.device);
    if (camera.device.empty()) {
        s.fail("device", "must not be empty");
    }
    s.readChoice("format", camera.format, {"mjpeg", "yuyv"});
    s.read("width", camera.width, 2, 16384);
    s.read("height", camera.height, 1, 16384);
    if (camera.width % 2 != 0) {
        s.fail("width", "must be even: the frame holds two equal eyes side by side");
    }
    s.read("fps", camera.fps, 1, 240);
    s.read("buffers", camera.buffers, 2, 32);
    s.read("frame_timeout_ms", camera.frameTimeoutMs, 100, 60000);
    s.read("reconnect_min_ms", camera.reconnectMinMs, 10, 600000);
    s.read("reconnect_max_ms", camera.reconnectMaxMs, 10, 3600000);
    if (camera.reconnectMaxMs < camera.reconnectMinMs) {
        s.fail("reconnect_max_ms", "must not be below reconnect_min_ms");
    }
    s.read("controls", camera.controls);
    s.finish();
}

void readCalibration(Section s, CalibrationConfig& calibration) {
    s.read("file", calibration.file);
    if (calibration.file.empty()) {
        s.fail("file", "must not be empty");
    }
    s.finish();
}

}  // namespace

Config parseConfig(std::string_view text, const std::string& fileName) {
    nlohmann::json root;
    try {
        root = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/true, /*ignore_comments=*/true);
    } catch (const nlohmann::json::parse_error& e) {
        throw ConfigError(fileName + ": not valid JSON: " + e.what());
    }
    if (!root.is_object()) {
        throw ConfigError(fileName + ": the top level must be a JSON object");
    }
    Config config;
    config.sourceFile = fileName;
    Section top(root, fileName, "");
    readLog(top.child("log"), config.log);
    readCamera(top.child("camera"), config.camera);
    readCalibration(top.child("calibration"), config.calibration);
    top.finish();
    return config;
}

Config loadConfig(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        throw ConfigError(path.string() + ": cannot read the configuration file");
    }
    std::ostringstream text;
    text << in.rdbuf();
    if (in.bad()) {
        throw ConfigError(path.string() + ": error while reading the configuration file");
    }
    return parseConfig(text.str(), path.string());
}

}  // namespace icewatch::config
