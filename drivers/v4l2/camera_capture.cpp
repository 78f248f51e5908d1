// Capture from the side-by-side stereo camera: negotiate, stream, hand out the freshest frame,
// survive the camera going away.
//
// Failures are values (CaptureError), not exceptions: a camera that vanishes is normal on a
// tower. Every failure closes everything (STREAMOFF, munmap, REQBUFS 0, close) so the next
// attempt starts clean; the back-off keeps a missing camera from being hammered, and the state
// logs keep a camera absent for a week down to two log lines.
//
// The driver is distrusted: buffer indices are checked against what we queued, error flags and
// short payloads are dropped before any byte is read, JPEG markers are checked before decoding,
// and the decoder drops anything libjpeg complains about. A frame is copied out of the mmap
// buffer (uncached memory, and the camera wants the buffer back) before the heavy decode.
#include "drivers/v4l2/camera_capture.hpp"

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace icewatch::v4l2 {

const char* captureErrorName(CaptureError error) {
    switch (error) {
        case CaptureError::kNone: return "none";
        case CaptureError::kNoDevice: return "no_device";
        case CaptureError::kPermission: return "permission";
        case CaptureError::kBusy: return "busy";
        case CaptureError::kNotCaptureDevice: return "not_capture_device";
        case CaptureError::kFormatUnsupported: return "format_unsupported";
        case CaptureError::kBadControl: return "bad_control";
        case CaptureError::kDisconnected: return "disconnected";
        case CaptureError::kStalled: return "stalled";
        case CaptureError::kNoValidFrame: return "no_valid_frame";
        case CaptureError::kIoError: return "io_error";
    }
    return "unknown";
}

ExitCode exitCodeFor(CaptureError error) {
    switch (error) {
        case CaptureError::kNone: return kExitOk;
        case CaptureError::kBadControl:
        case CaptureError::kFormatUnsupported: return kExitConfig;
        case CaptureError::kNoDevice:
        case CaptureError::kPermission:
        case CaptureError::kNotCaptureDevice: return kExitUnavailable;
        case CaptureError::kBusy:
        case CaptureError::kDisconnected:
        case CaptureError::kStalled:
        case CaptureError::kNoValidFrame: return kExitTempFail;
        case CaptureError::kIoError: return kExitIoErr;
    }
    return kExitSoftware;
}

std::uint64_t CaptureStats::droppedTotal() const {
    std::uint64_t total = 0;
    for (std::uint64_t n : dropped) total += n;
    return total;
}

CameraCapture::CameraCapture(config::CameraConfig config, Syscalls& syscalls, std::string path,
                             CaptureOptions options)
    : config_(std::move(config)),
      syscalls_(syscalls),
      path_(std::move(path)),
      options_(std::move(options)),
      device_(syscalls_),
      backoff_(config_.reconnectMinMs),
      log_(log::get("v4l2")),
      stateLog_(log_),
      modeLog_(log_) {}

CameraCapture::~CameraCapture() { closeAll(); }

void CameraCapture::stop() {
    closeAll();
    retryPending_ = false;
}

void CameraCapture::closeAll() {
    if (device_.isOpen() && streaming_) {
        device_.streamOff();  // fails with ENODEV after an unplug; closing frees all the same
    }
    for (Buffer& b : buffers_) {
        device_.unmap(b.address, b.length);
    }
    if (device_.isOpen() && !buffers_.empty()) {
        unsigned none = 0;
        device_.requestBuffers(none);
    }
    buffers_.clear();
    device_.close();
    streaming_ = false;
}

CaptureError CameraCapture::fail(CaptureError error, const std::string& what) {
    closeAll();
    retryPending_ = true;
    lastError_ = what;
    const bool configuration = error == CaptureError::kBadControl || error == CaptureError::kFormatUnsupported;
    stateLog_.report(std::string("offline:") + captureErrorName(error), configuration ? spdlog::level::err : spdlog::level::warn,
                     "camera " + path_ + " offline (" + captureErrorName(error) + "): " + what +
                         (configuration ? "; fix the configuration" : "; retrying with back-off"));
    return error;
}

CaptureError CameraCapture::failErrno(int ret, const std::string& call) {
    const std::string what = call + " on " + path_ + ": " + std::strerror(-ret);
    switch (-ret) {
        case ENODEV:
        case ENXIO:
            ++stats_.disconnects;
            return fail(CaptureError::kDisconnected, what);
        case EBUSY: return fail(CaptureError::kBusy, what);
        default: return fail(CaptureError::kIoError, what);
    }
}

CaptureError CameraCapture::start() {
    closeAll();
    const CaptureError error = startDevice();
    if (error != CaptureError::kNone) {
        return error;
    }
    streaming_ = true;
    retryPending_ = false;
    backoff_ = std::chrono::milliseconds(config_.reconnectMinMs);
    ++stats_.starts;
    stateLog_.report("streaming", spdlog::level::info,
                     "camera " + path_ + " (" + mode_.card + ", " + mode_.driver + ") streaming " +
                         formatName(mode_.format) + " " + std::to_string(mode_.width) + "x" +
                         std::to_string(mode_.height) + " at " + std::to_string(mode_.fps) + " fps with " +
                         std::to_string(mode_.buffers) + " buffers");
    return CaptureError::kNone;
}

CaptureError CameraCapture::startDevice() {
    mode_ = NegotiatedMode{};
    int ret = device_.open(path_);
    if (ret < 0) {
        const std::string what = "cannot open " + path_ + ": " + std::strerror(-ret);
        if (ret == -EACCES || ret == -EPERM) return fail(CaptureError::kPermission, what);
        if (ret == -EBUSY) return fail(CaptureError::kBusy, what);
        if (ret == -ENOENT || ret == -ENODEV || ret == -ENXIO) return fail(CaptureError::kNoDevice, what);
        return fail(CaptureError::kIoError, what);
    }
    Capability cap;
    ret = device_.queryCapability(cap);
    if (ret == -ENOTTY || ret == -EINVAL) {
        return fail(CaptureError::kNotCaptureDevice, path_ + " is not a V4L2 device (VIDIOC_QUERYCAP refused)");
    }
    if (ret < 0) return failErrno(ret, "VIDIOC_QUERYCAP");
    if (!cap.isVideoCapture() || !cap.hasStreaming()) {
        return fail(CaptureError::kNotCaptureDevice,
                    path_ + " (" + cap.cardName() + ") offers no video capture with streaming I/O; "
                            "UVC cameras have a second, metadata-only node: use the other /dev/videoN");
    }
    mode_.driver = cap.driverName();
    mode_.card = cap.cardName();
    mode_.busInfo = cap.busInfo();
    if (CaptureError e = negotiateFormat(); e != CaptureError::kNone) return e;
    if (CaptureError e = applyControls(); e != CaptureError::kNone) return e;
    if (CaptureError e = mapBuffers(); e != CaptureError::kNone) return e;
    ret = device_.streamOn();
    if (ret < 0) return failErrno(ret, "VIDIOC_STREAMON");
    return CaptureError::kNone;
}

CaptureError CameraCapture::negotiateFormat() {
    const PixelFormat wanted = parseFormatName(config_.format).value_or(PixelFormat::kMjpeg);
    std::vector<FormatDescription> formats;
    int ret = device_.enumFormats(formats);
    if (ret < 0) return failErrno(ret, "VIDIOC_ENUM_FMT");
    const bool offered = std::any_of(formats.begin(), formats.end(),
                                     [&](const FormatDescription& f) { return f.fourcc == fourcc(wanted); });
    if (!offered) {
        std::string list;
        for (const FormatDescription& f : formats) list += (list.empty() ? "" : ", ") + fourccText(f.fourcc);
        return fail(CaptureError::kFormatUnsupported,
                    path_ + " does not offer " + fourccText(fourcc(wanted)) + " (it offers " + list + ")");
    }
    v4l2_pix_format pix{};
    pix.width = static_cast<std::uint32_t>(config_.width);
    pix.height = static_cast<std::uint32_t>(config_.height);
    pix.pixelformat = fourcc(wanted);
    pix.field = V4L2_FIELD_NONE;
    ret = device_.setFormat(pix);
    if (ret < 0) return failErrno(ret, "VIDIOC_S_FMT");
    // Read back what is in effect: drivers adjust S_FMT silently, and what S_FMT answered is not
    // always what the hardware streams.
    ret = device_.getFormat(pix);
    if (ret < 0) return failErrno(ret, "VIDIOC_G_FMT");
    const auto got = fromFourcc(pix.pixelformat);
    if (!got) {
        return fail(CaptureError::kFormatUnsupported,
                    path_ + " switched to " + fourccText(pix.pixelformat) + ", which icewatch cannot decode");
    }
    if (pix.width % 2 != 0 || pix.width == 0 || pix.height == 0) {
        return fail(CaptureError::kFormatUnsupported, path_ + " chose a " + std::to_string(pix.width) + "x" +
                                                          std::to_string(pix.height) +
                                                          " frame, which cannot hold two equal eyes");
    }
    mode_.format = *got;
    mode_.width = static_cast<int>(pix.width);
    mode_.height = static_cast<int>(pix.height);
    mode_.substituted = *got != wanted || mode_.width != config_.width || mode_.height != config_.height;
    const std::string asked = formatName(wanted) + " " + std::to_string(config_.width) + "x" +
                              std::to_string(config_.height);
    const std::string given = formatName(*got) + " " + std::to_string(mode_.width) + "x" + std::to_string(mode_.height);
    if (mode_.substituted) {
        modeLog_.report("substituted " + given, spdlog::level::warn,
                        "camera " + path_ + " substituted " + given + " for the configured " + asked +
                            "; check `icewatch info` for the modes it really offers");
    } else {
        modeLog_.report("as configured", spdlog::level::debug, "camera " + path_ + " accepted " + asked);
    }
    FrameInterval interval;
    ret = device_.setFrameRate(config_.fps, interval);
    if (ret == 0 && interval.numerator != 0) {
        mode_.fps = static_cast<int>(interval.denominator / interval.numerator);
    } else if (ret < 0 && ret != -ENOTTY && ret != -EINVAL) {
        return failErrno(ret, "VIDIOC_S_PARM");
    }
    return CaptureError::kNone;
}

CaptureError CameraCapture::applyControls() {
    if (config_.controls.empty()) {
        return CaptureError::kNone;
    }
    std::vector<ControlInfo> available;
    const int ret = device_.queryControls(available);
    if (ret < 0) return failErrno(ret, "VIDIOC_QUERYCTRL");
    // Automatic modes first: a manual exposure or white balance only takes once its "auto"
    // switch is off.
    std::vector<std::pair<std::string, std::int64_t>> order(config_.controls.begin(), config_.controls.end());
    std::stable_partition(order.begin(), order.end(),
                          [](const auto& c) { return c.first.find("auto") != std::string::npos; });
    for (const auto& [name, value] : order) {
        const auto it = std::find_if(available.begin(), available.end(),
                                     [&name = name](const ControlInfo& c) { return c.name == name; });
        if (it == available.end()) {
            std::string names;
            for (const ControlInfo& c : available) names += (names.empty() ? "" : ", ") + c.name;
            return fail(CaptureError::kBadControl,
                        "camera.controls." + name + ": " + path_ + " has no such control (it has: " + names + ")");
        }
        bool valid = value >= it->minimum && value <= it->maximum;
        if (valid && it->type == V4L2_CTRL_TYPE_MENU) {
            // An init-capture: clang before 16 cannot capture a structured binding.
            valid = std::any_of(it->menu.begin(), it->menu.end(),
                                [&value = value](const auto& m) { return m.first == value; });
        }
        if (!valid) {
            return fail(CaptureError::kBadControl, "camera.controls." + name + ": " + std::to_string(value) +
                                                       " is outside what " + path_ + " accepts (" +
                                                       std::to_string(it->minimum) + " to " +
                                                       std::to_string(it->maximum) + ")");
        }
        const int set = device_.setControl(it->id, static_cast<std::int32_t>(value));
        if (set == -ENODEV) return failErrno(set, "VIDIOC_S_CTRL");
        if (set < 0) {
            // UVC refuses some controls in some states (EACCES, EIO); the stream is still useful.
            log_->warn("camera {}: setting {} to {} failed: {}", path_, name, value, std::strerror(-set));
        }
        std::int32_t readBack = 0;
        if (device_.getControl(it->id, readBack) == 0) {
            mode_.controls[name] = readBack;
        }
    }
    return CaptureError::kNone;
}

CaptureError CameraCapture::mapBuffers() {
    unsigned count = static_cast<unsigned>(config_.buffers);
    int ret = device_.requestBuffers(count);
    if (ret < 0) return failErrno(ret, "VIDIOC_REQBUFS");
    if (count == 0) {
        return fail(CaptureError::kIoError, path_ + " granted no buffers");
    }
    if (count < static_cast<unsigned>(config_.buffers)) {
        // Drivers may grant fewer than asked; fewer buffers only means fewer frames to choose from.
        log_->debug("camera {}: {} of {} buffers granted", path_, count, config_.buffers);
    }
    mode_.buffers = count;
    for (unsigned i = 0; i < count; ++i) {
        v4l2_buffer b;
        ret = device_.queryBuffer(i, b);
        if (ret < 0) return failErrno(ret, "VIDIOC_QUERYBUF");
        int error = 0;
        void* address = device_.map(b.length, static_cast<off_t>(b.m.offset), error);
        if (address == nullptr) return failErrno(-error, "mmap of buffer " + std::to_string(i));
        buffers_.push_back({address, b.length, false});
    }
    for (unsigned i = 0; i < count; ++i) {
        ret = device_.queueBuffer(i);
        if (ret < 0) return failErrno(ret, "VIDIOC_QBUF");
    }
    return CaptureError::kNone;
}

CaptureError CameraCapture::ensureStreaming() {
    if (streaming_) {
        return CaptureError::kNone;
    }
    if (retryPending_) {
        options_.sleep(backoff_);
        backoff_ = std::min(backoff_ * 2, std::chrono::milliseconds(config_.reconnectMaxMs));
    }
    return start();
}

CaptureError CameraCapture::waitForFrame() {
    // EINTR is a signal, not a camera problem; a bounded number of retries keeps a signal storm
    // from spinning here forever.
    for (int attempt = 0; attempt < 100; ++attempt) {
        short revents = 0;
        const int ret = device_.waitReadable(config_.frameTimeoutMs, revents);
        if (ret == -EINTR) {
            ++stats_.interrupts;
            continue;
        }
        if (ret < 0) return failErrno(ret, "poll");
        if (ret == 0) {
            ++stats_.stalls;
            return fail(CaptureError::kStalled, "no frame within " + std::to_string(config_.frameTimeoutMs) + " ms");
        }
        if ((revents & (POLLERR | POLLHUP | POLLNVAL)) != 0) {
            ++stats_.disconnects;
            return fail(CaptureError::kDisconnected, std::string("poll reports ") +
                                                         ((revents & POLLHUP) != 0 ? "POLLHUP" : "POLLERR") +
                                                         " (camera unplugged or stream broken)");
        }
        return CaptureError::kNone;
    }
    return fail(CaptureError::kIoError, "poll interrupted 100 times in a row");
}

CaptureError CameraCapture::giveBack(unsigned index) {
    buffers_[index].held = false;
    const int ret = device_.queueBuffer(index);
    return ret < 0 ? failErrno(ret, "VIDIOC_QBUF") : CaptureError::kNone;
}

CaptureError CameraCapture::takeBuffer(v4l2_buffer& b, bool& nothingQueued) {
    nothingQueued = false;
    const int ret = device_.dequeueBuffer(b);
    if (ret == -EAGAIN) {
        nothingQueued = true;
        return CaptureError::kNoValidFrame;
    }
    if (ret < 0) return failErrno(ret, "VIDIOC_DQBUF");
    auto drop = [&](DropReason reason, bool giveItBack) {
        ++stats_.dropped[static_cast<std::size_t>(reason)];
        log_->debug("camera {}: dropped frame {} ({})", path_, b.sequence, dropReasonName(reason));
        if (giveItBack) {
            const CaptureError e = giveBack(b.index);
            if (e != CaptureError::kNone) return e;
        }
        return CaptureError::kNoValidFrame;
    };
    // An index we never queued or already hold cannot be trusted, nor re-queued.
    if (b.index >= buffers_.size() || buffers_[b.index].held) {
        return drop(DropReason::kBadIndex, false);
    }
    buffers_[b.index].held = true;
    if ((b.flags & V4L2_BUF_FLAG_ERROR) != 0) {
        return drop(DropReason::kErrorFlag, true);
    }
    if (b.bytesused == 0 || b.bytesused > buffers_[b.index].length) {
        return drop(DropReason::kShortFrame, true);
    }
    const auto* data = static_cast<const std::uint8_t*>(buffers_[b.index].address);
    if (auto bad = checkFrameBytes(mode_.format, data, b.bytesused, mode_.width, mode_.height)) {
        return drop(*bad, true);
    }
    return CaptureError::kNone;
}

CaptureError CameraCapture::grab(CapturedFrame& frame) {
    if (CaptureError e = ensureStreaming(); e != CaptureError::kNone) return e;
    if (CaptureError e = waitForFrame(); e != CaptureError::kNone) return e;
    // Drain: keep the newest valid buffer, give every older one straight back.
    bool haveNewest = false;
    v4l2_buffer newest{};
    for (;;) {
        v4l2_buffer b;
        bool nothingQueued = false;
        const CaptureError e = takeBuffer(b, nothingQueued);
        if (nothingQueued) break;
        if (e == CaptureError::kNoValidFrame) continue;
        if (e != CaptureError::kNone) return e;
        if (haveNewest) {
            ++stats_.skipped;
            if (CaptureError g = giveBack(newest.index); g != CaptureError::kNone) return g;
        }
        newest = b;
        haveNewest = true;
    }
    if (!haveNewest) {
        lastError_ = "every frame the camera sent was dropped";
        return CaptureError::kNoValidFrame;
    }
    const auto start = std::chrono::steady_clock::now();
    const auto* data = static_cast<const std::uint8_t*>(buffers_[newest.index].address);
    frameBytes_.assign(data, data + newest.bytesused);
    if (CaptureError g = giveBack(newest.index); g != CaptureError::kNone) return g;
    // A fresh image each frame, which the frame's eyes then view: no copy of the eyes, and
    // nothing of the size of a frame stays behind between bursts.
    cv::Mat bgr;
    if (auto bad = decoder_.decode(mode_.format, frameBytes_.data(), frameBytes_.size(), mode_.width, mode_.height,
                                   bgr)) {
        ++stats_.dropped[static_cast<std::size_t>(*bad)];
        lastError_ = "frame " + std::to_string(newest.sequence) + " dropped: " + decoder_.message();
        log_->debug("camera {}: {}", path_, lastError_);
        return CaptureError::kNoValidFrame;
    }
    frame.pair = sideBySideViews(bgr);
    frame.sequence = newest.sequence;
    frame.timestampUs = std::int64_t{newest.timestamp.tv_sec} * 1000000 + newest.timestamp.tv_usec;
    frame.bytes = frameBytes_.size();
    frame.decodeMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    ++stats_.delivered;
    return CaptureError::kNone;
}

CaptureError CameraCapture::nextRaw(RawFrame& frame) {
    if (CaptureError e = ensureStreaming(); e != CaptureError::kNone) return e;
    for (;;) {
        v4l2_buffer b;
        bool nothingQueued = false;
        const CaptureError e = takeBuffer(b, nothingQueued);
        if (nothingQueued) {
            if (CaptureError w = waitForFrame(); w != CaptureError::kNone) return w;
            continue;
        }
        if (e != CaptureError::kNone) return e;
        const auto* data = static_cast<const std::uint8_t*>(buffers_[b.index].address);
        frame.bytes.assign(data, data + b.bytesused);
        frame.sequence = b.sequence;
        frame.timestampUs = std::int64_t{b.timestamp.tv_sec} * 1000000 + b.timestamp.tv_usec;
        if (CaptureError g = giveBack(b.index); g != CaptureError::kNone) return g;
        ++stats_.delivered;
        return CaptureError::kNone;
    }
}

}  // namespace icewatch::v4l2
