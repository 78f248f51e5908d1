#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "core/config/scada_config.hpp"
#include "core/pictures/picture_scale.hpp"
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

// The image-health check every burst frame passes before it is measured (daemon section). It
// asks whether the camera saw anything at all; whether the object can be measured is the volume
// gate's, on the object's region of the averaged capture (volume.max_saturated_percent,
// max_new_saturated_percent, min_contrast). Whole-frame figures cannot judge the object: a sky
// clipped behind a blade that is well exposed is most of the frame, white ice on a blade against
// a plain sky leaves a frame in focus as little detail as blur would, and a small blade against a
// plain sky leaves the frame's grey varying as little as fog would.
struct ImageHealthConfig {
    double minMeanLevel = 25.0;          // mean grey level (0-255) below this: dark
    double maxSaturatedPercent = 98.0;   // share of pixels at 250 or more above this: washed out
    double minSharpness = 0.0;           // variance of the Laplacian at 1/4 scale below this: blurred (0: off)
    double minContrast = 2.0;            // standard deviation of grey below this: blank (a covered lens, thick fog)
};

struct DaemonConfig {
    int intervalS = 600;                 // measurement cadence
    // Frames grabbed per cycle (freshest each), averaged into one capture: the registration's
    // error on a blade falls as 1/√N (the tracks' scatter halved from 16 to 64 frames).
    int burstFrames = 64;
    int baselineFrames = 128;            // frames averaged into the baseline (commissioning is not in a hurry)
    int minFrames = 16;                  // healthy, still frames the average needs
    int cameraCheckS = 5;                // camera health is looked at this often between cycles
    int maxRefusedS = 0;                 // this long without an ok result is a fault; 0: three intervals
    std::string stateDir = "/var/lib/icewatch";
    ImageHealthConfig health;
};

// daemon.max_refused_s as it applies: 0 stands for three measurement intervals.
int maxRefusedS(const DaemonConfig& daemon);

// Levels none / warning / alarm on one metric, each with set and clear thresholds (hysteresis).
struct AlarmConfig {
    std::string metric = "volume_mm3";   // volume_mm3 or mean_thickness_mm
    // estimate: the levels follow the measured value. upper_bound: the value plus its expanded
    // uncertainty, so that ice the measurement cannot rule out raises the level too.
    std::string judge = "estimate";
    double warningSet = 50000.0;         // in the metric's unit
    double warningClear = 30000.0;
    double alarmSet = 200000.0;
    double alarmClear = 150000.0;
    int warningHoldS = 1800;             // a level is kept at least this long before it is lowered
    int alarmHoldS = 3600;
    bool latch = false;                  // alarm stays until reset (SIGUSR2, POST /v1/alarm/reset)
};

struct GpioConfig {
    // gpiochip name or /dev path; "none" drives no outputs; "fake" records in memory; fake:FILE
    // appends every transition to FILE (tests, desk PCs).
    std::string chip = "gpiochip0";
    int alarmLine = 17;                  // energised = no ice alarm
    int healthyLine = 27;                // energised = system healthy
    bool activeLow = false;
    std::string consumer = "icewatchd";
};

struct HttpConfig {
    bool enabled = true;
    std::string address = "127.0.0.1";
    int port = 8088;                     // 0: any free port (tests)
    // Every POST needs "Authorization: Bearer TOKEN". Empty: the token is read from token_file,
    // which icewatchd creates with a random token (mode 0640) when it does not exist.
    std::string token;
    std::string tokenFile = "/etc/icewatch/http-token";
};

// True for 127.0.0.0/8, ::1 and localhost: addresses no other machine can reach.
bool isLoopbackAddress(const std::string& address);

struct HistoryConfig {
    int retentionDays = 365;
};

struct Config {
    std::string sourceFile;  // where it was loaded from, for messages
    LogConfig log;
    CameraConfig camera;
    CalibrationConfig calibration;
    volume::Parameters volume;  // the "volume" section: every tunable of the volume chain
    stereo::Parameters stereo;  // the matcher's parameters (core/stereo/parameters.hpp documents them)
    DaemonConfig daemon;
    AlarmConfig alarm;
    GpioConfig gpio;
    HttpConfig http;
    HistoryConfig history;
    pictures::PictureScale pictures;  // the scale of the pictures for people
    ScadaConfig scada;  // core/config/scada_config.hpp
};

// Parses and validates a whole configuration; fileName is only used in messages. JSON with //
// comments is accepted (the shipped file documents itself). Throws ConfigError (exit 78) naming
// every problem, one per line. Paths stay as written (loadConfig resolves them).
Config parseConfig(std::string_view text, const std::string& fileName);

// Reads and parses a file. A missing or unreadable file is a ConfigError too: the daemon must not
// start on defaults when its configuration is gone. Relative paths in it (calibration.file,
// daemon.state_dir, http.token_file, fake:DIR devices and GPIO files, the MQTT files) are taken
// from the file's own directory. Every problem is in the message, one per line.
Config loadConfig(const std::filesystem::path& path);

// Everything wrong with a file, each problem naming the file and the key (none: loadConfig
// succeeds with `config`). Never throws for the file's content.
struct ConfigCheck {
    Config config;  // as far as it could be read; defaults elsewhere
    std::vector<std::string> problems;
};
ConfigCheck checkConfigFile(const std::filesystem::path& path);

// Only the gpio section of a file, for `icewatchd --fail-safe-outputs`, which must drop the lines
// whatever else the file gets wrong. Never throws: on any problem (said in problem) it returns
// the compiled-in defaults.
GpioConfig loadGpioSection(const std::filesystem::path& path, std::string& problem);

}  // namespace icewatch::config
