#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <string_view>

#include "core/volume/parameters.hpp"
#include "core/stereo/parameters.hpp"

namespace icewatch::config {

// Every key is documented, with its default, in config/icewatch.json. The defaults here and
// there must agree (a test loads that file and compares).

struct LogConfig {
    std::string level = "info";  // trace, debug, info, warn, error
};

struct CameraConfig {
    // /dev/videoN, a /dev/v4l/by-id/... link, or fake:DIR to replay a recording through the fake
    // V4L2 device (tests, the demo, a desk PC without the camera).
    std::string device = "/dev/video0";
    std::string format = "mjpeg";       // mjpeg or yuyv (YUYV runs 1-3 fps over USB 2.0)
    int width = 2560;                   // side-by-side frame width (both eyes)
    int height = 720;
    int fps = 30;
    int buffers = 4;                    // mmap buffers requested; the driver may grant fewer
    int frameTimeoutMs = 2000;          // no frame for this long = stalled camera
    int reconnectMinMs = 500;           // back-off after the camera vanished, doubling ...
    int reconnectMaxMs = 30000;         // ... up to this
    // V4L2 controls by name as the driver lists them ("exposure_time_absolute": 300, ...).
    // HBVCAM units deliver near-black frames with default exposure: set exposure explicitly.
    std::map<std::string, std::int64_t> controls;
};

struct CalibrationConfig {
    // The stereo calibration the daemon rectifies with (OpenCV FileStorage, `icewatch calibrate`).
    // Its eye size must match camera.width/2 x camera.height.
    std::string file = "/etc/icewatch/calibration.yaml";
};

struct Config {
    std::string sourceFile;  // where it was loaded from, for messages
    LogConfig log;
    CameraConfig camera;
    CalibrationConfig calibration;
    volume::Parameters volume;  // the "volume" section: every tunable of the volume chain
    stereo::Parameters stereo;  // the matcher's parameters (core/stereo/parameters.hpp documents them)
};

// Parses and validates a whole configuration; fileName is only used in messages. JSON with //
// comments is accepted (the shipped file documents itself). Throws ConfigError (exit 78).
Config parseConfig(std::string_view text, const std::string& fileName);

// Reads and parses a file. A missing or unreadable file is a ConfigError too: the daemon must not
// start on defaults when its configuration is gone.
Config loadConfig(const std::filesystem::path& path);

}  // namespace icewatch::config
