// icewatch acquire: open the camera as the daemon would, take the freshest frames, report how
// acquisition went (frames, eye size, drops and why, negotiated mode, timing).
#include <algorithm>
#include <iostream>

#include <nlohmann/json.hpp>

#include "drivers/v4l2/camera_capture.hpp"
#include "drivers/v4l2/device_seam.hpp"
#include "tools/icewatch/camera_cli.hpp"
#include "tools/icewatch/command.hpp"

namespace icewatch::cli {

namespace {

struct AcquireOptions {
    std::string device;
    std::string configFile;
    int frames = 10;
    double timeoutS = 30.0;
    bool json = false;
};

int runAcquire(const AcquireOptions& o) {
    const config::CameraConfig camera = cameraConfig(o.configFile, o.device);
    v4l2::DeviceSeam seam = v4l2::makeDeviceSeam(camera.device);
    v4l2::CameraCapture capture(camera, *seam.syscalls, seam.path);

    const auto start = std::chrono::steady_clock::now();
    v4l2::CapturedFrame frame;
    int eyeWidth = 0;
    int eyeHeight = 0;
    double decodeMsSum = 0.0;
    double decodeMsMax = 0.0;
    std::int64_t firstTimestampUs = 0;
    std::int64_t lastTimestampUs = 0;
    nlohmann::json sequences = nlohmann::json::array();
    const v4l2::CaptureError error = collectFrames(o.frames, o.timeoutS, [&] {
        const v4l2::CaptureError e = capture.grab(frame);
        if (e == v4l2::CaptureError::kNone) {
            eyeWidth = frame.pair.left.cols;
            eyeHeight = frame.pair.left.rows;
            decodeMsSum += frame.decodeMs;
            decodeMsMax = std::max(decodeMsMax, frame.decodeMs);
            if (sequences.empty()) firstTimestampUs = frame.timestampUs;
            lastTimestampUs = frame.timestampUs;
            sequences.push_back(frame.sequence);
        }
        return e;
    });
    const double elapsedS = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (error != v4l2::CaptureError::kNone) {
        throwCaptureError(error, capture);
    }
    const v4l2::CaptureStats& stats = capture.stats();
    const auto delivered = static_cast<double>(stats.delivered);
    nlohmann::json result = {
        {"device", camera.device},
        {"requested",
         {{"format", camera.format}, {"width", camera.width}, {"height", camera.height}, {"fps", camera.fps},
          {"buffers", camera.buffers}}},
        {"negotiated", modeJson(capture.mode())},
        {"frames", stats.delivered},
        {"eye", {{"width", eyeWidth}, {"height", eyeHeight}}},
        {"dropped", droppedJson(stats)},
        {"skipped_for_newer", stats.skipped},
        {"sequences", sequences},
        {"reconnects", stats.starts > 0 ? stats.starts - 1 : 0},
        {"disconnects", stats.disconnects},
        {"stalls", stats.stalls},
        {"timing",
         {{"elapsed_s", elapsedS},
          {"frames_per_s", elapsedS > 0 ? delivered / elapsedS : 0.0},
          {"camera_span_ms", static_cast<double>(lastTimestampUs - firstTimestampUs) / 1000.0},
          {"decode_ms_mean", delivered > 0 ? decodeMsSum / delivered : 0.0},
          {"decode_ms_max", decodeMsMax}}},
    };
    if (o.json) {
        std::cout << result.dump() << "\n";
    } else {
        std::cout << "acquired " << stats.delivered << " frames of " << capture.mode().width << "x"
                  << capture.mode().height << " (" << eyeWidth << "x" << eyeHeight << " per eye) from " << camera.device
                  << " in " << elapsedS << " s; dropped " << stats.droppedTotal() << ", reconnects "
                  << result["reconnects"] << "\n";
    }
    return 0;
}

}  // namespace

void addAcquireCommand(CLI::App& app, const GlobalOptions& /*global*/, RunFunction& run) {
    CLI::App* cmd = app.add_subcommand("acquire", "grab the freshest frames from the camera and report acquisition");
    auto o = std::make_shared<AcquireOptions>();
    cmd->add_option("--device", o->device, "camera: /dev/videoN, /dev/v4l/by-id/..., or fake:DIR (a recording)");
    cmd->add_option("--config", o->configFile, "configuration file (its camera section is used)");
    cmd->add_option("--frames", o->frames, "how many frames to grab")->check(CLI::Range(1, 100000));
    cmd->add_option("--timeout-s", o->timeoutS, "give up after this many seconds")->check(CLI::PositiveNumber);
    cmd->add_flag("--json", o->json, "print one JSON object");
    cmd->callback([&run, o] { run = [o] { return runAcquire(*o); }; });
}

}  // namespace icewatch::cli
