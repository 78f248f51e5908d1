#pragma once

#include <array>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include <opencv2/core.hpp>

#include "core/common/exit_codes.hpp"
#include "core/common/side_by_side.hpp"
#include "core/config/config.hpp"
#include "drivers/log/log.hpp"
#include "drivers/v4l2/frame_decoder.hpp"
#include "drivers/v4l2/recording.hpp"
#include "drivers/v4l2/v4l2_device.hpp"

namespace icewatch::v4l2 {

// What went wrong, as the reconnect loop and a supervisor need to know it.
enum class CaptureError {
    kNone,
    kNoDevice,           // the node is not there: unplugged, or a wrong path
    kPermission,         // the node exists but may not be opened (udev rule, group)
    kBusy,               // another process is streaming from it
    kNotCaptureDevice,   // not a V4L2 node with video capture and streaming
    kFormatUnsupported,  // the configured pixel format is not offered, or cannot be decoded
    kBadControl,         // a configured control is unknown to the camera or out of its range
    kDisconnected,       // ENODEV or POLLERR/POLLHUP while streaming: the camera went away
    kStalled,            // no frame within camera.frame_timeout_ms
    kNoValidFrame,       // frames arrived but every one was dropped (stats() says why)
    kIoError,            // any other failing system call
};
// "no_device", "stalled", ... (JSON, log lines).
const char* captureErrorName(CaptureError error);
// The exit status of a command that gives up on this error.
ExitCode exitCodeFor(CaptureError error);

// What the driver agreed to, read back from it (never assumed from the request).
struct NegotiatedMode {
    PixelFormat format = PixelFormat::kMjpeg;
    int width = 0;   // the side-by-side frame
    int height = 0;
    int fps = 0;     // from S_PARM's answer; 0 when the driver does not say
    unsigned buffers = 0;
    bool substituted = false;  // size or format differ from the configuration
    std::string driver;        // "uvcvideo"
    std::string card;
    std::string busInfo;
    std::map<std::string, std::int32_t> controls;  // configured controls as read back
};

// Counters over the capture's life, across reconnects.
struct CaptureStats {
    std::uint64_t delivered = 0;  // frames handed out
    std::uint64_t skipped = 0;    // valid frames passed over because a newer one was queued
    std::array<std::uint64_t, kDropReasonCount> dropped{};
    std::uint64_t disconnects = 0;
    std::uint64_t stalls = 0;
    std::uint64_t interrupts = 0;  // EINTR while waiting (retried)
    std::uint64_t starts = 0;      // successful starts; more than one means reconnects

    std::uint64_t droppedTotal() const;
};

// One decoded frame, split into the two eyes (left eye = left half).
struct CapturedFrame {
    StereoPair pair;               // BGR, CV_8UC3, each eye width/2 x height
    std::uint32_t sequence = 0;    // the driver's frame counter (restarts with each stream)
    std::int64_t timestampUs = 0;  // the driver's timestamp (CLOCK_MONOTONIC for uvcvideo)
    std::size_t bytes = 0;         // as delivered
    double decodeMs = 0.0;         // decode and split (measured, for the figures)
};

// One frame exactly as delivered, undecoded (recordings).
struct RawFrame {
    std::vector<std::uint8_t> bytes;
    std::uint32_t sequence = 0;
    std::int64_t timestampUs = 0;
};

struct CaptureOptions {
    // How the reconnect back-off waits; tests record the delays instead of sleeping.
    std::function<void(std::chrono::milliseconds)> sleep = [](std::chrono::milliseconds d) {
        std::this_thread::sleep_for(d);
    };
};

// Live capture from a V4L2 camera sending both eyes side by side (mmap streaming).
//
// Configuration (CameraConfig) is kept apart from live state (fd, buffers, negotiated mode), so
// an unplug or a stall is handled by closing everything and starting again. grab() does that by
// itself: after a failure the next call waits the back-off (camera.reconnect_min_ms, doubling up
// to reconnect_max_ms) and reopens; a failure that repeats is logged once per change of state.
//
//   auto seam = v4l2::makeDeviceSeam(config.camera.device);
//   v4l2::CameraCapture camera(config.camera, *seam.syscalls, seam.path);
//   v4l2::CapturedFrame frame;
//   if (camera.grab(frame) == v4l2::CaptureError::kNone) { use(frame.pair); }
//
// Not thread-safe: one thread owns a CameraCapture.
class CameraCapture {
public:
    // path: what to open (/dev/videoN, /dev/v4l/by-id/...); syscalls must outlive the capture.
    CameraCapture(config::CameraConfig config, Syscalls& syscalls, std::string path, CaptureOptions options = {});
    ~CameraCapture();
    CameraCapture(const CameraCapture&) = delete;
    CameraCapture& operator=(const CameraCapture&) = delete;

    // Opens, negotiates, applies controls, maps buffers and starts streaming. grab() calls it
    // when needed; calling it first reports configuration problems early.
    CaptureError start();
    // Stops streaming and releases the device.
    void stop();
    bool isStreaming() const { return streaming_; }

    // The freshest frame: waits (poll, camera.frame_timeout_ms) for the camera, takes everything
    // it has queued, keeps the newest valid frame and re-queues the rest, copies that frame out of
    // the mmap buffer, re-queues it, then decodes and splits it. Reconnects as described above.
    // kNone: frame is filled. kNoValidFrame: everything was dropped; call again. Anything else:
    // the camera is offline; call again to retry after the back-off.
    CaptureError grab(CapturedFrame& frame);
    // The next frame in order, undecoded (only the cheap checks): for recordings.
    CaptureError nextRaw(RawFrame& frame);

    const NegotiatedMode& mode() const { return mode_; }
    const CaptureStats& stats() const { return stats_; }
    // What the last error was, for a person.
    const std::string& lastError() const { return lastError_; }
    // The back-off the next reconnect attempt will wait.
    std::chrono::milliseconds nextBackoff() const { return backoff_; }

private:
    struct Buffer {
        void* address = nullptr;
        std::size_t length = 0;
        bool held = false;  // dequeued by us, not yet given back
    };

    CaptureError ensureStreaming();
    CaptureError startDevice();
    CaptureError negotiateFormat();
    CaptureError applyControls();
    CaptureError mapBuffers();
    CaptureError waitForFrame();
    // Takes one buffer from the driver: kNone with buffer filled and held, kNoValidFrame when it
    // was dropped, or an error. nothingQueued is set when the driver had nothing (EAGAIN).
    CaptureError takeBuffer(v4l2_buffer& buffer, bool& nothingQueued);
    CaptureError giveBack(unsigned index);
    CaptureError fail(CaptureError error, const std::string& what);
    CaptureError failErrno(int ret, const std::string& call);
    void closeAll();

    const config::CameraConfig config_;
    Syscalls& syscalls_;
    const std::string path_;
    const CaptureOptions options_;

    // Live state: rebuilt by every start.
    V4l2Device device_;
    std::vector<Buffer> buffers_;
    NegotiatedMode mode_;
    bool streaming_ = false;

    // Across restarts.
    CaptureStats stats_;
    std::chrono::milliseconds backoff_;
    bool retryPending_ = false;
    std::string lastError_;
    FrameDecoder decoder_;
    std::vector<std::uint8_t> frameBytes_;
    std::shared_ptr<spdlog::logger> log_;
    log::StateLog stateLog_;
    log::StateLog modeLog_;
};

}  // namespace icewatch::v4l2
