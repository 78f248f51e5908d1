// The fake UVC camera: the kernel side of the syscall seam, modelled on uvcvideo + videobuf2.
//
// It keeps what a driver can observe of a real device: a node that can vanish (unplug) and come
// back as a new device instance, one streaming owner, vb2's buffer states (dequeued -> queued ->
// done) and its error returns (EBUSY, EINVAL, EAGAIN, ENODEV), uvcvideo's format snapping and its
// behaviour when no buffer is queued (the frame is lost). Buffer memory is a memfd, so the
// driver's mmap() is a real mapping and the bytes it reads are the ones the device wrote.
//
// Time: at recording pace frames become due at the recording's timestamps on the steady clock and
// poll() really sleeps; at fast pace a virtual clock jumps straight to the next due frame whenever
// the consumer waits, so tests never sleep. Faults are keyed to the number of frames produced.
#include "drivers/v4l2/fake_uvc_device.hpp"

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cstring>
#include <thread>

#include <fcntl.h>
#include <linux/videodev2.h>
#include <sys/mman.h>
#include <unistd.h>

#include "core/common/error.hpp"
#include "drivers/v4l2/v4l2_device.hpp"

namespace icewatch::v4l2 {

struct FakeUvcDevice::Buffer {
    enum class State { kDequeued, kQueued, kDone };
    std::size_t offset = 0;
    std::size_t length = 0;
    State state = State::kDequeued;
    std::uint32_t bytesUsed = 0;
    std::uint32_t flags = 0;
    std::uint32_t sequence = 0;
    std::uint32_t reportedIndex = 0;
    std::int64_t timestampUs = 0;
};

struct FakeUvcDevice::Control {
    std::uint32_t id;
    std::string name;
    std::uint32_t type;
    std::int32_t minimum;
    std::int32_t maximum;
    std::int32_t step;
    std::int32_t defaultValue;
    std::vector<std::string> menu;  // empty entries are items the camera does not offer
    std::int32_t value;
};

namespace {

constexpr std::int64_t kNever = INT64_MAX;

std::vector<int> intervalsFor(int maxFps) {
    // uvcvideo lists the intervals the camera's descriptors carry; these are the HBVCAM's.
    return maxFps >= 30 ? std::vector<int>{30, 25, 20, 15, 10, 5} : std::vector<int>{10, 5};
}

std::size_t pageAligned(std::size_t bytes) {
    const auto page = static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
    return (bytes + page - 1) / page * page;
}

std::size_t sizeImage(int width, int height) {
    // uvcvideo takes dwMaxVideoFrameBufferSize from the camera; these cameras announce 2 bytes/pixel
    // for MJPEG as for YUYV.
    return static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 2;
}

}  // namespace

const std::vector<FakeMode>& hbvcamModes() {
    static const std::vector<FakeMode> modes = [] {
        std::vector<FakeMode> m;
        for (PixelFormat f : {PixelFormat::kMjpeg, PixelFormat::kYuyv}) {
            m.push_back({f, 1280, 480, 30});
            m.push_back({f, 2560, 720, 30});
            m.push_back({f, 3840, 1080, 30});
            m.push_back({f, 3840, 1520, 10});
        }
        return m;
    }();
    return modes;
}

FakeUvcDevice::FakeUvcDevice(Recording recording, FakeUvcOptions options)
    : recording_(std::move(recording)),
      options_(std::move(options)),
      faultUsed_(options_.faults.size(), false),
      format_(recording_.format),
      width_(recording_.width),
      height_(recording_.height),
      fps_(recording_.fps),
      epoch_(std::chrono::steady_clock::now()) {
    if (recording_.frames.empty()) {
        throw InvalidInput(recording_.dir.string() + ": the recording has no frames to replay");
    }
    for (std::size_t i = 0; i < recording_.frames.size(); ++i) {
        frames_.push_back(recording_.readFrame(i));
    }
    // uvcvideo's names since Linux 5.x (the v4l2 core's standard names); v4l2-ctl prints them as
    // brightness, auto_exposure, exposure_time_absolute, white_balance_automatic, ...
    controls_ = {
        {V4L2_CID_BRIGHTNESS, "Brightness", V4L2_CTRL_TYPE_INTEGER, -64, 64, 1, 0, {}, 0},
        {V4L2_CID_CONTRAST, "Contrast", V4L2_CTRL_TYPE_INTEGER, 0, 64, 1, 32, {}, 32},
        {V4L2_CID_SATURATION, "Saturation", V4L2_CTRL_TYPE_INTEGER, 0, 128, 1, 64, {}, 64},
        {V4L2_CID_AUTO_WHITE_BALANCE, "White Balance, Automatic", V4L2_CTRL_TYPE_BOOLEAN, 0, 1, 1, 1, {}, 1},
        {V4L2_CID_GAIN, "Gain", V4L2_CTRL_TYPE_INTEGER, 0, 100, 1, 0, {}, 0},
        {V4L2_CID_POWER_LINE_FREQUENCY, "Power Line Frequency", V4L2_CTRL_TYPE_MENU, 0, 2, 1, 1,
         {"Disabled", "50 Hz", "60 Hz"}, 1},
        {V4L2_CID_WHITE_BALANCE_TEMPERATURE, "White Balance Temperature", V4L2_CTRL_TYPE_INTEGER, 2800, 6500, 1,
         4600, {}, 4600},
        {V4L2_CID_EXPOSURE_AUTO, "Auto Exposure", V4L2_CTRL_TYPE_MENU, 0, 3, 1, 3,
         {"", "Manual Mode", "", "Aperture Priority Mode"}, 3},
        {V4L2_CID_EXPOSURE_ABSOLUTE, "Exposure Time, Absolute", V4L2_CTRL_TYPE_INTEGER, 1, 5000, 1, 156, {}, 156},
    };
    std::sort(controls_.begin(), controls_.end(), [](const Control& a, const Control& b) { return a.id < b.id; });
}

FakeUvcDevice::~FakeUvcDevice() {
    freeBuffers();
    for (const auto& [address, length] : mappings_) {
        ::munmap(address, length);  // a driver that leaked its mappings must not leak them past us
    }
}

std::string FakeUvcDevice::devicePath() const { return recording_.dir.string(); }

std::size_t FakeUvcDevice::framesProduced() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return produced_;
}

int FakeUvcDevice::successfulOpens() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return successfulOpens_;
}

int FakeUvcDevice::openFds() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return static_cast<int>(fds_.size());
}

std::size_t FakeUvcDevice::liveMappings() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return mappings_.size();
}

std::int64_t FakeUvcDevice::controlValue(const std::string& name) const {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const Control& c : controls_) {
        if (controlVariableName(c.name) == name) return c.value;
    }
    throw std::out_of_range("fake device has no control " + name);
}

// ---- the node and its file descriptors ----------------------------------------------------------

int FakeUvcDevice::open(const std::string& path, int flags) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (path != devicePath()) {
        return -ENOENT;
    }
    if (unplugged_) {
        if (failedOpensWhileUnplugged_ < options_.replugAfterOpenAttempts) {
            ++failedOpensWhileUnplugged_;
            return -ENOENT;  // the node is gone until the camera is back
        }
        unplugged_ = false;
        failedOpensWhileUnplugged_ = 0;
    }
    const int fd = nextFd_++;
    fds_[fd] = OpenFile{generation_, flags};
    ++successfulOpens_;
    return fd;
}

int FakeUvcDevice::close(int fd) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (fds_.erase(fd) == 0) {
        return -EBADF;
    }
    if (fd == ownerFd_) {
        freeBuffers();  // vb2 releases the queue when its owner closes
    }
    return 0;
}

bool FakeUvcDevice::fdLive(int fd) const {
    const auto it = fds_.find(fd);
    return it != fds_.end() && it->second.generation == generation_ && !unplugged_;
}

void FakeUvcDevice::unplugNow() {
    unplugged_ = true;
    failedOpensWhileUnplugged_ = 0;
    ++generation_;  // every open file now refers to a device that no longer exists
    freeBuffers();
}

void FakeUvcDevice::freeBuffers() {
    if (memory_ != nullptr) {
        ::munmap(memory_, memoryBytes_);
        memory_ = nullptr;
        memoryBytes_ = 0;
    }
    if (memfd_ >= 0) {
        ::close(memfd_);  // mappings the driver still holds stay valid, as with vb2 after disconnect
        memfd_ = -1;
    }
    buffers_.clear();
    queued_.clear();
    done_.clear();
    ownerFd_ = -1;
    streaming_ = false;
    stalled_ = false;
}

// ---- memory -------------------------------------------------------------------------------------

void* FakeUvcDevice::mmap(std::size_t length, int prot, int flags, int fd, off_t offset, int* error) {
    std::lock_guard<std::mutex> lock(mutex_);
    *error = 0;
    if (fds_.count(fd) == 0) {
        *error = EBADF;
        return nullptr;
    }
    if (!fdLive(fd)) {
        *error = ENODEV;
        return nullptr;
    }
    const auto buffer = std::find_if(buffers_.begin(), buffers_.end(), [&](const Buffer& b) {
        return b.offset == static_cast<std::size_t>(offset);
    });
    if (buffer == buffers_.end() || length == 0 || length > buffer->length || (flags & MAP_SHARED) == 0) {
        *error = EINVAL;  // vb2: unknown offset, too long, or not shared
        return nullptr;
    }
    void* address = ::mmap(nullptr, length, prot, flags, memfd_, offset);
    if (address == MAP_FAILED) {
        *error = errno;
        return nullptr;
    }
    mappings_[address] = length;
    return address;
}

int FakeUvcDevice::munmap(void* address, std::size_t length) {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto it = mappings_.find(address);
    if (it == mappings_.end() || it->second != length) {
        return -EINVAL;
    }
    ::munmap(address, length);
    mappings_.erase(it);
    return 0;
}

// ---- time and frames ----------------------------------------------------------------------------

std::int64_t FakeUvcDevice::nowUs() const {
    if (options_.pace == FakeUvcOptions::Pace::kFast) {
        return virtualNowUs_;
    }
    return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now() - epoch_).count();
}

std::int64_t FakeUvcDevice::frameIntervalUs() const { return 1000000 / std::max(recording_.fps, 1); }

std::int64_t FakeUvcDevice::dueUs(std::size_t position) const {
    const std::size_t n = frames_.size();
    if (!options_.loop && position >= n) {
        return kNever;
    }
    const auto& f = recording_.frames;
    const std::int64_t loopUs = f.back().timestampUs - f.front().timestampUs + frameIntervalUs();
    return timelineBaseUs_ + static_cast<std::int64_t>(position / n) * loopUs + f[position % n].timestampUs -
           f.front().timestampUs;
}

bool FakeUvcDevice::faultAt(FakeFault::Kind kind, std::size_t frame, int* count) {
    for (std::size_t i = 0; i < options_.faults.size(); ++i) {
        const FakeFault& f = options_.faults[i];
        if (!faultUsed_[i] && f.kind == kind && f.atFrame == frame) {
            faultUsed_[i] = true;
            if (count != nullptr) *count = f.count;
            return true;
        }
    }
    return false;
}

void FakeUvcDevice::produceDueFrames() {
    while (streaming_ && !stalled_ && !unplugged_ && dueUs(position_) <= nowUs()) {
        if (!produceOne(dueUs(position_))) {
            break;
        }
    }
}

bool FakeUvcDevice::produceOne(std::int64_t timestampUs) {
    if (faultAt(FakeFault::Kind::kUnplug, produced_)) {
        unplugNow();
        return false;
    }
    if (faultAt(FakeFault::Kind::kStall, produced_)) {
        stalled_ = true;
        return false;
    }
    const std::vector<std::uint8_t>& bytes = frames_[position_ % frames_.size()];
    const std::size_t frameNo = produced_;
    ++position_;
    ++produced_;
    const std::uint32_t sequence = sequence_++;
    if (queued_.empty()) {
        return true;  // uvcvideo has nowhere to put it: the frame is lost
    }
    const unsigned index = queued_.front();
    queued_.pop_front();
    Buffer& b = buffers_[index];
    std::size_t used = std::min(bytes.size(), b.length);
    b.flags = V4L2_BUF_FLAG_MAPPED | V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC | V4L2_BUF_FLAG_TSTAMP_SRC_SOE;
    if (bytes.size() > b.length) {
        b.flags |= V4L2_BUF_FLAG_ERROR;  // uvcvideo: payload overflowed the buffer
    }
    if (faultAt(FakeFault::Kind::kErrorFlag, frameNo)) {
        used /= 2;
        b.flags |= V4L2_BUF_FLAG_ERROR;
    }
    if (faultAt(FakeFault::Kind::kTruncatedJpeg, frameNo)) {
        used /= 2;
    }
    if (faultAt(FakeFault::Kind::kZeroBytes, frameNo)) {
        used = 0;
    }
    b.reportedIndex = faultAt(FakeFault::Kind::kUnknownIndex, frameNo) ? static_cast<std::uint32_t>(buffers_.size() + 7)
                                                                        : index;
    std::memcpy(memory_ + b.offset, bytes.data(), used);
    b.bytesUsed = static_cast<std::uint32_t>(used);
    b.sequence = sequence;
    b.timestampUs = timestampUs;
    b.state = Buffer::State::kDone;
    done_.push_back(index);
    return true;
}

short FakeUvcDevice::pollEvents(int fd) const {
    if (fds_.count(fd) == 0) {
        return POLLNVAL;
    }
    if (!fdLive(fd)) {
        return POLLERR | POLLHUP;  // uvcvideo after disconnect
    }
    if (!streaming_ || fd != ownerFd_) {
        return POLLERR;  // vb2: not streaming on this file
    }
    return done_.empty() ? 0 : static_cast<short>(POLLIN | POLLRDNORM);
}

int FakeUvcDevice::poll(pollfd* fds, nfds_t count, int timeoutMs) {
    std::unique_lock<std::mutex> lock(mutex_);
    for (std::size_t i = 0; i < options_.faults.size(); ++i) {
        const FakeFault& f = options_.faults[i];
        if (!faultUsed_[i] && f.kind == FakeFault::Kind::kInterrupt && f.atFrame <= produced_) {
            faultUsed_[i] = true;
            return -EINTR;  // a signal arrived while waiting
        }
    }
    const std::int64_t deadlineUs = timeoutMs < 0 ? kNever : nowUs() + std::int64_t{timeoutMs} * 1000;
    for (;;) {
        produceDueFrames();
        int ready = 0;
        for (nfds_t i = 0; i < count; ++i) {
            fds[i].revents = static_cast<short>(pollEvents(fds[i].fd) & (fds[i].events | POLLERR | POLLHUP | POLLNVAL));
            ready += fds[i].revents != 0 ? 1 : 0;
        }
        if (ready > 0 || timeoutMs == 0) {
            return ready;
        }
        if (waitLocked(-1, deadlineUs == kNever ? -1 : static_cast<int>((deadlineUs - nowUs() + 999) / 1000), lock) ==
            0) {
            return 0;
        }
    }
}

// Lets time pass until the next frame is due or the timeout ends; returns 0 on timeout, 1 when
// there may be something new.
int FakeUvcDevice::waitLocked(int /*fd*/, int timeoutMs, std::unique_lock<std::mutex>& lock) {
    const std::int64_t now = nowUs();
    const std::int64_t deadlineUs = timeoutMs < 0 ? kNever : now + std::int64_t{timeoutMs} * 1000;
    const bool frameComing = streaming_ && !stalled_ && !unplugged_ && dueUs(position_) != kNever;
    if (options_.pace == FakeUvcOptions::Pace::kFast) {
        if (frameComing && !queued_.empty()) {
            int burst = 1;
            faultAt(FakeFault::Kind::kBurst, produced_, &burst);
            virtualNowUs_ = std::max(virtualNowUs_, dueUs(position_ + static_cast<std::size_t>(std::max(burst, 1)) - 1));
            return 1;
        }
        if (deadlineUs != kNever) {
            virtualNowUs_ = deadlineUs;  // the whole timeout passes, instantly
        }
        return 0;
    }
    if (now >= deadlineUs) {
        return 0;
    }
    std::int64_t wakeUs = std::min(deadlineUs, frameComing ? dueUs(position_) : now + 50000);
    wakeUs = std::max(wakeUs, now);
    lock.unlock();
    std::this_thread::sleep_for(std::chrono::microseconds(wakeUs - now));
    lock.lock();
    return 1;
}

// ---- ioctls -------------------------------------------------------------------------------------

int FakeUvcDevice::ioctl(int fd, unsigned long request, void* arg) {
    std::unique_lock<std::mutex> lock(mutex_);
    if (fds_.count(fd) == 0) {
        return -EBADF;
    }
    if (!fdLive(fd)) {
        return -ENODEV;
    }
    return handleIoctl(fd, request, arg, lock);
}

int FakeUvcDevice::handleIoctl(int fd, unsigned long request, void* arg, std::unique_lock<std::mutex>& lock) {
    switch (request) {
        case VIDIOC_QUERYCAP: {
            auto* cap = static_cast<v4l2_capability*>(arg);
            std::memset(cap, 0, sizeof *cap);
            std::snprintf(reinterpret_cast<char*>(cap->driver), sizeof cap->driver, "uvcvideo");
            std::snprintf(reinterpret_cast<char*>(cap->card), sizeof cap->card, "HBVCAM Stereo Camera: HBVCAM");
            std::snprintf(reinterpret_cast<char*>(cap->bus_info), sizeof cap->bus_info, "usb-0000:00:14.0-2");
            cap->version = (6u << 16) | (1u << 8);
            cap->device_caps = V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_STREAMING | V4L2_CAP_EXT_PIX_FORMAT;
            cap->capabilities = cap->device_caps | V4L2_CAP_META_CAPTURE | V4L2_CAP_DEVICE_CAPS;
            return 0;
        }
        case VIDIOC_ENUM_FMT:
            return enumFormat(arg);
        case VIDIOC_ENUM_FRAMESIZES:
            return enumFrameSizes(arg);
        case VIDIOC_ENUM_FRAMEINTERVALS:
            return enumFrameIntervals(arg);
        case VIDIOC_G_FMT: {
            auto* f = static_cast<v4l2_format*>(arg);
            if (f->type != V4L2_BUF_TYPE_VIDEO_CAPTURE) return -EINVAL;
            v4l2_format current{};
            current.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
            current.fmt.pix.width = static_cast<std::uint32_t>(width_);
            current.fmt.pix.height = static_cast<std::uint32_t>(height_);
            current.fmt.pix.pixelformat = fourcc(format_);
            *f = current;
            return setFormat(f, false);
        }
        case VIDIOC_S_FMT:
            return setFormat(arg, true);
        case VIDIOC_TRY_FMT:
            return setFormat(arg, false);
        case VIDIOC_G_PARM:
        case VIDIOC_S_PARM: {
            auto* p = static_cast<v4l2_streamparm*>(arg);
            if (p->type != V4L2_BUF_TYPE_VIDEO_CAPTURE) return -EINVAL;
            if (request == VIDIOC_S_PARM) {
                if (streaming_) return -EBUSY;
                const auto& tpf = p->parm.capture.timeperframe;
                const double wanted = tpf.numerator == 0 ? 1000.0 : double(tpf.denominator) / tpf.numerator;
                int maxFps = 30;
                for (const FakeMode& m : hbvcamModes()) {
                    if (m.format == format_ && m.width == width_ && m.height == height_) maxFps = m.maxFps;
                }
                int best = maxFps;
                for (int fps : intervalsFor(maxFps)) {
                    if (std::abs(fps - wanted) < std::abs(best - wanted)) best = fps;
                }
                fps_ = best;
            }
            std::memset(&p->parm, 0, sizeof p->parm);
            p->parm.capture.capability = V4L2_CAP_TIMEPERFRAME;
            p->parm.capture.timeperframe = {1, static_cast<std::uint32_t>(fps_)};
            p->parm.capture.readbuffers = 0;
            return 0;
        }
        case VIDIOC_REQBUFS:
            return requestBuffers(fd, arg);
        case VIDIOC_QUERYBUF: {
            auto* b = static_cast<v4l2_buffer*>(arg);
            if (b->type != V4L2_BUF_TYPE_VIDEO_CAPTURE || b->index >= buffers_.size()) return -EINVAL;
            const Buffer& buf = buffers_[b->index];
            const std::uint32_t index = b->index;
            std::memset(b, 0, sizeof *b);
            b->index = index;
            b->type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
            b->memory = V4L2_MEMORY_MMAP;
            b->m.offset = static_cast<std::uint32_t>(buf.offset);
            b->length = static_cast<std::uint32_t>(buf.length);
            b->flags = V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC | (buf.state == Buffer::State::kQueued ? V4L2_BUF_FLAG_QUEUED : 0);
            return 0;
        }
        case VIDIOC_QBUF:
            if (fd != ownerFd_) return -EBUSY;
            return queueBuffer(arg);
        case VIDIOC_DQBUF:
            if (fd != ownerFd_) return -EBUSY;
            return dequeueBuffer(fd, arg, lock);
        case VIDIOC_STREAMON:
            if (*static_cast<int*>(arg) != V4L2_BUF_TYPE_VIDEO_CAPTURE) return -EINVAL;
            return streamOn(fd);
        case VIDIOC_STREAMOFF:
            if (*static_cast<int*>(arg) != V4L2_BUF_TYPE_VIDEO_CAPTURE) return -EINVAL;
            if (fd != ownerFd_) return -EBUSY;
            streamOff();
            return 0;
        case VIDIOC_QUERYCTRL:
        case VIDIOC_QUERYMENU:
        case VIDIOC_G_CTRL:
        case VIDIOC_S_CTRL:
            return controlIoctl(request, arg);
        default:
            return -ENOTTY;
    }
}

int FakeUvcDevice::enumFormat(void* arg) const {
    auto* d = static_cast<v4l2_fmtdesc*>(arg);
    if (d->type != V4L2_BUF_TYPE_VIDEO_CAPTURE || d->index > 1) return -EINVAL;
    const std::uint32_t index = d->index;
    std::memset(d, 0, sizeof *d);
    d->index = index;
    d->type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    if (index == 0) {
        d->pixelformat = V4L2_PIX_FMT_MJPEG;
        d->flags = V4L2_FMT_FLAG_COMPRESSED;
        std::snprintf(reinterpret_cast<char*>(d->description), sizeof d->description, "Motion-JPEG");
    } else {
        d->pixelformat = V4L2_PIX_FMT_YUYV;
        std::snprintf(reinterpret_cast<char*>(d->description), sizeof d->description, "YUYV 4:2:2");
    }
    return 0;
}

int FakeUvcDevice::enumFrameSizes(void* arg) const {
    auto* s = static_cast<v4l2_frmsizeenum*>(arg);
    const auto format = fromFourcc(s->pixel_format);
    if (!format) return -EINVAL;
    std::uint32_t seen = 0;
    for (const FakeMode& m : hbvcamModes()) {
        if (m.format == *format && seen++ == s->index) {
            s->type = V4L2_FRMSIZE_TYPE_DISCRETE;
            s->discrete = {static_cast<std::uint32_t>(m.width), static_cast<std::uint32_t>(m.height)};
            return 0;
        }
    }
    return -EINVAL;
}

int FakeUvcDevice::enumFrameIntervals(void* arg) const {
    auto* i = static_cast<v4l2_frmivalenum*>(arg);
    const auto format = fromFourcc(i->pixel_format);
    if (!format) return -EINVAL;
    for (const FakeMode& m : hbvcamModes()) {
        if (m.format == *format && std::uint32_t(m.width) == i->width && std::uint32_t(m.height) == i->height) {
            const std::vector<int> fps = intervalsFor(m.maxFps);
            if (i->index >= fps.size()) return -EINVAL;
            i->type = V4L2_FRMIVAL_TYPE_DISCRETE;
            i->discrete = {1, static_cast<std::uint32_t>(fps[i->index])};
            return 0;
        }
    }
    return -EINVAL;
}

int FakeUvcDevice::setFormat(void* arg, bool apply) {
    auto* f = static_cast<v4l2_format*>(arg);
    if (f->type != V4L2_BUF_TYPE_VIDEO_CAPTURE) return -EINVAL;
    if (apply && !buffers_.empty()) return -EBUSY;  // vb2: the queue is busy while buffers exist
    v4l2_pix_format& pix = f->fmt.pix;
    // uvcvideo falls back to the first format for an unknown FourCC and picks the frame size
    // with the smallest area difference (uvc_v4l2_try_format).
    const PixelFormat format = fromFourcc(pix.pixelformat).value_or(PixelFormat::kMjpeg);
    const FakeMode* best = nullptr;
    std::int64_t bestDistance = INT64_MAX;
    for (const FakeMode& m : hbvcamModes()) {
        if (m.format != format) continue;
        const std::int64_t w = m.width, h = m.height, rw = pix.width, rh = pix.height;
        const std::int64_t distance = w * h + rw * rh - 2 * std::min(w, rw) * std::min(h, rh);
        if (distance < bestDistance) {
            bestDistance = distance;
            best = &m;
        }
    }
    PixelFormat chosenFormat = best->format;
    int width = best->width;
    int height = best->height;
    if (apply && options_.substituteMode) {
        chosenFormat = recording_.format;  // some firmwares answer with what they stream, whatever was asked
        width = recording_.width;
        height = recording_.height;
    }
    std::memset(&f->fmt, 0, sizeof f->fmt);
    pix.width = static_cast<std::uint32_t>(width);
    pix.height = static_cast<std::uint32_t>(height);
    pix.pixelformat = fourcc(chosenFormat);
    pix.field = V4L2_FIELD_NONE;
    pix.bytesperline = chosenFormat == PixelFormat::kYuyv ? static_cast<std::uint32_t>(width * 2) : 0;
    pix.sizeimage = static_cast<std::uint32_t>(sizeImage(width, height));
    pix.colorspace = V4L2_COLORSPACE_SRGB;
    if (apply) {
        format_ = chosenFormat;
        width_ = width;
        height_ = height;
        fps_ = std::min(fps_, best->maxFps);
    }
    return 0;
}

int FakeUvcDevice::requestBuffers(int fd, void* arg) {
    auto* r = static_cast<v4l2_requestbuffers*>(arg);
    if (r->type != V4L2_BUF_TYPE_VIDEO_CAPTURE || r->memory != V4L2_MEMORY_MMAP) return -EINVAL;
    if (ownerFd_ >= 0 && ownerFd_ != fd) return -EBUSY;  // another file streams
    if (streaming_) return -EBUSY;
    if (!mappings_.empty()) return -EBUSY;  // vb2: buffers still mapped cannot be freed
    freeBuffers();
    r->capabilities = V4L2_BUF_CAP_SUPPORTS_MMAP;
    if (r->count == 0) {
        return 0;
    }
    const unsigned count = std::min(r->count, options_.maxBuffers);
    const std::size_t length = pageAligned(sizeImage(width_, height_));
    memfd_ = ::memfd_create("fake-uvc-buffers", MFD_CLOEXEC);
    if (memfd_ < 0) return -errno;
    memoryBytes_ = length * count;
    if (::ftruncate(memfd_, static_cast<off_t>(memoryBytes_)) < 0) {
        const int e = errno;
        freeBuffers();
        return -e;
    }
    void* memory = ::mmap(nullptr, memoryBytes_, PROT_READ | PROT_WRITE, MAP_SHARED, memfd_, 0);
    if (memory == MAP_FAILED) {
        const int e = errno;
        memoryBytes_ = 0;
        freeBuffers();
        return -e;
    }
    memory_ = static_cast<std::uint8_t*>(memory);
    buffers_.resize(count);
    for (unsigned i = 0; i < count; ++i) {
        buffers_[i].offset = i * length;
        buffers_[i].length = sizeImage(width_, height_);
    }
    ownerFd_ = fd;
    r->count = count;
    return 0;
}

int FakeUvcDevice::queueBuffer(void* arg) {
    auto* b = static_cast<v4l2_buffer*>(arg);
    if (b->type != V4L2_BUF_TYPE_VIDEO_CAPTURE || b->memory != V4L2_MEMORY_MMAP || b->index >= buffers_.size()) {
        return -EINVAL;
    }
    Buffer& buf = buffers_[b->index];
    if (buf.state != Buffer::State::kDequeued) return -EINVAL;  // vb2: not in dequeued state
    buf.state = Buffer::State::kQueued;
    queued_.push_back(b->index);
    b->flags |= V4L2_BUF_FLAG_QUEUED;
    return 0;
}

int FakeUvcDevice::dequeueBuffer(int fd, void* arg, std::unique_lock<std::mutex>& lock) {
    auto* b = static_cast<v4l2_buffer*>(arg);
    if (b->type != V4L2_BUF_TYPE_VIDEO_CAPTURE || b->memory != V4L2_MEMORY_MMAP) return -EINVAL;
    if (!streaming_) return -EINVAL;
    produceDueFrames();
    while (done_.empty()) {
        if ((fds_[fd].flags & O_NONBLOCK) != 0) return -EAGAIN;
        if (waitLocked(fd, -1, lock) == 0 && done_.empty() && (stalled_ || !streaming_)) return -EIO;
        if (!fdLive(fd)) return -ENODEV;
        produceDueFrames();
    }
    const unsigned index = done_.front();
    done_.pop_front();
    Buffer& buf = buffers_[index];
    std::memset(b, 0, sizeof *b);
    b->index = buf.reportedIndex;
    b->type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    b->memory = V4L2_MEMORY_MMAP;
    b->bytesused = buf.bytesUsed;
    b->flags = buf.flags;
    b->field = V4L2_FIELD_NONE;
    b->timestamp.tv_sec = buf.timestampUs / 1000000;
    b->timestamp.tv_usec = buf.timestampUs % 1000000;
    b->sequence = buf.sequence;
    b->m.offset = static_cast<std::uint32_t>(buf.offset);
    b->length = static_cast<std::uint32_t>(buf.length);
    if (buf.reportedIndex != index) {
        buf.state = Buffer::State::kQueued;  // the bogus report loses nothing on the device side
        queued_.push_back(index);
    } else {
        buf.state = Buffer::State::kDequeued;
    }
    return 0;
}

int FakeUvcDevice::streamOn(int fd) {
    if (fd != ownerFd_ || buffers_.empty()) return -EINVAL;
    if (streaming_) return 0;
    streaming_ = true;
    stalled_ = false;
    sequence_ = 0;
    // The first frame arrives one interval after STREAMON.
    timelineBaseUs_ = 0;
    timelineBaseUs_ = nowUs() + frameIntervalUs() - dueUs(position_);
    return 0;
}

void FakeUvcDevice::streamOff() {
    streaming_ = false;
    stalled_ = false;  // a restarted stream is what cures a stalled camera
    queued_.clear();
    done_.clear();
    for (Buffer& b : buffers_) b.state = Buffer::State::kDequeued;
}

int FakeUvcDevice::controlIoctl(unsigned long request, void* arg) {
    auto find = [this](std::uint32_t id) -> Control* {
        for (Control& c : controls_) {
            if (c.id == id) return &c;
        }
        return nullptr;
    };
    auto valueOf = [&](std::uint32_t id) {
        const Control* c = find(id);
        return c != nullptr ? c->value : 0;
    };
    switch (request) {
        case VIDIOC_QUERYCTRL: {
            auto* q = static_cast<v4l2_queryctrl*>(arg);
            const Control* c = nullptr;
            if ((q->id & V4L2_CTRL_FLAG_NEXT_CTRL) != 0) {
                const std::uint32_t after = q->id & ~(V4L2_CTRL_FLAG_NEXT_CTRL | V4L2_CTRL_FLAG_NEXT_COMPOUND);
                for (const Control& candidate : controls_) {
                    if (candidate.id > after) {
                        c = &candidate;
                        break;
                    }
                }
            } else {
                c = find(q->id);
            }
            if (c == nullptr) return -EINVAL;
            std::memset(q, 0, sizeof *q);
            q->id = c->id;
            q->type = c->type;
            std::snprintf(reinterpret_cast<char*>(q->name), sizeof q->name, "%s", c->name.c_str());
            q->minimum = c->minimum;
            q->maximum = c->maximum;
            q->step = c->step;
            q->default_value = c->defaultValue;
            // uvcvideo marks a manual control inactive while its automatic twin is on.
            if ((c->id == V4L2_CID_EXPOSURE_ABSOLUTE && valueOf(V4L2_CID_EXPOSURE_AUTO) != V4L2_EXPOSURE_MANUAL) ||
                (c->id == V4L2_CID_WHITE_BALANCE_TEMPERATURE && valueOf(V4L2_CID_AUTO_WHITE_BALANCE) != 0)) {
                q->flags |= V4L2_CTRL_FLAG_INACTIVE;
            }
            return 0;
        }
        case VIDIOC_QUERYMENU: {
            auto* m = static_cast<v4l2_querymenu*>(arg);
            const Control* c = find(m->id);
            if (c == nullptr || c->type != V4L2_CTRL_TYPE_MENU || m->index >= c->menu.size() ||
                c->menu[m->index].empty()) {
                return -EINVAL;
            }
            std::snprintf(reinterpret_cast<char*>(m->name), sizeof m->name, "%s", c->menu[m->index].c_str());
            return 0;
        }
        case VIDIOC_G_CTRL: {
            auto* v = static_cast<v4l2_control*>(arg);
            const Control* c = find(v->id);
            if (c == nullptr) return -EINVAL;
            v->value = c->value;
            return 0;
        }
        default: {  // VIDIOC_S_CTRL
            auto* v = static_cast<v4l2_control*>(arg);
            Control* c = find(v->id);
            if (c == nullptr) return -EINVAL;
            if (c->type == V4L2_CTRL_TYPE_MENU) {
                if (v->value < c->minimum || v->value > c->maximum || c->menu[std::size_t(v->value)].empty()) {
                    return -EINVAL;
                }
                c->value = v->value;
                return 0;
            }
            c->value = std::clamp(v->value, c->minimum, c->maximum);  // uvcvideo clamps integers
            v->value = c->value;
            return 0;
        }
    }
}

}  // namespace icewatch::v4l2
