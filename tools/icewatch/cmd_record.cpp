// icewatch record: write what the camera sends, frame by frame and byte for byte, as a recording
// the fake device can replay (tests, the demo, a desk PC without the camera).
#include <iostream>

#include <nlohmann/json.hpp>

#include "core/common/error.hpp"
#include "drivers/v4l2/camera_capture.hpp"
#include "drivers/v4l2/device_seam.hpp"
#include "drivers/v4l2/recording.hpp"
#include "tools/icewatch/camera_cli.hpp"
#include "tools/icewatch/command.hpp"
#include "tools/icewatch/terminal.hpp"

namespace icewatch::cli {

namespace {

struct RecordOptions {
    std::string device;
    std::string configFile;
    std::string mode;
    std::string format;
    int fps = 0;
    int frames = 30;
    std::string out;
    double timeoutS = 30.0;
    bool json = false;
    bool force = false;
};

int runRecord(const RecordOptions& o) {
    checkOutputDirectory(o.out, o.force, "--out");
    config::CameraConfig camera = cameraConfig(o.configFile, o.device);
    if (!o.mode.empty()) parseMode(o.mode, camera.width, camera.height);
    if (!o.format.empty()) camera.format = o.format;
    if (o.fps > 0) camera.fps = o.fps;
    v4l2::DeviceSeam seam = v4l2::makeDeviceSeam(camera.device);
    v4l2::CameraCapture capture(camera, *seam.syscalls, seam.path);
    if (const v4l2::CaptureError e = capture.start(); e != v4l2::CaptureError::kNone &&
                                                      e != v4l2::CaptureError::kNoDevice &&
                                                      e != v4l2::CaptureError::kDisconnected) {
        throwCaptureError(e, capture);
    }
    std::unique_ptr<v4l2::RecordingWriter> writer;
    v4l2::RawFrame frame;
    const v4l2::CaptureError error = collectFrames(o.frames, o.timeoutS, [&] {
        const v4l2::CaptureError e = capture.nextRaw(frame);
        if (e == v4l2::CaptureError::kNone) {
            if (!writer) {  // the mode is known once streaming: record what the camera agreed to
                const v4l2::NegotiatedMode& m = capture.mode();
                writer = std::make_unique<v4l2::RecordingWriter>(o.out, camera.device, m.format, m.width, m.height,
                                                                 m.fps > 0 ? m.fps : camera.fps);
            }
            writer->add(frame.bytes.data(), frame.bytes.size(), frame.timestampUs);
        }
        return e;
    });
    if (error != v4l2::CaptureError::kNone) {
        throwCaptureError(error, capture);
    }
    writer->finish();
    const v4l2::CaptureStats& stats = capture.stats();
    const nlohmann::json result = {{"out", o.out},
                                   {"device", camera.device},
                                   {"frames", writer->recording().frames.size()},
                                   {"negotiated", modeJson(capture.mode())},
                                   {"dropped", droppedJson(stats)},
                                   {"reconnects", stats.starts > 0 ? stats.starts - 1 : 0}};
    if (o.json) {
        std::cout << result.dump() << "\n";
    } else {
        std::cout << "recorded " << result["frames"] << " frames (" << v4l2::formatName(capture.mode().format) << " "
                  << capture.mode().width << "x" << capture.mode().height << ") to " << o.out << "; dropped "
                  << stats.droppedTotal() << "\n";
    }
    return 0;
}

}  // namespace

void addRecordCommand(CLI::App& app, const GlobalOptions& /*global*/, RunFunction& run) {
    CLI::App* cmd = app.add_subcommand("record", "write the camera's frames, exactly as delivered, to a recording");
    auto o = std::make_shared<RecordOptions>();
    cmd->add_option("--device", o->device, "/dev/videoN, /dev/v4l/by-id/..., or fake:DIR (a recording)");
    cmd->add_option("--config", o->configFile, "configuration file (its camera section is used)");
    cmd->add_option("--mode", o->mode, "side-by-side frame size, e.g. 2560x720");
    cmd->add_option("--format", o->format, "pixel format")->check(CLI::IsMember({"mjpeg", "yuyv"}));
    cmd->add_option("--fps", o->fps, "frame rate to ask for")->check(CLI::Range(1, 240));
    cmd->add_option("--frames", o->frames, "how many frames to record")->check(CLI::Range(1, 100000));
    cmd->add_option("--out", o->out, "directory to write (must not hold a recording)")->required();
    cmd->add_option("--timeout-s", o->timeoutS, "give up after this many seconds")->check(CLI::PositiveNumber);
    cmd->add_flag("--json", o->json, "print one JSON object");
    cmd->add_flag("--force", o->force, "record into a directory that holds other files (a recording is never replaced)");
    cmd->callback([&run, o] { run = [o] { return runRecord(*o); }; });
}

}  // namespace icewatch::cli
