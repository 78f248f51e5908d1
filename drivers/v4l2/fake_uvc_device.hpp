#pragma once

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "drivers/v4l2/recording.hpp"
#include "drivers/v4l2/syscalls.hpp"

namespace icewatch::v4l2 {

// A fault the fake device plays at a given point of the stream. atFrame counts the frames the
// device has produced since it was created (0 = the first one), across re-opens.
struct FakeFault {
    enum class Kind {
        kUnplug,         // instead of frame atFrame the device vanishes: ENODEV, POLLERR|POLLHUP, ENOENT on open
        kErrorFlag,      // frame atFrame arrives half-filled with V4L2_BUF_FLAG_ERROR (a USB payload error)
        kZeroBytes,      // frame atFrame arrives with bytesused = 0
        kTruncatedJpeg,  // frame atFrame arrives cut in half, no error flag (the driver missed the loss)
        kStall,          // from frame atFrame on nothing arrives until the stream is restarted
        kInterrupt,      // the first poll() once atFrame frames were produced fails with EINTR
        kUnknownIndex,   // frame atFrame is reported under a buffer index that does not exist
        kBurst,          // frame atFrame and the next `count - 1` arrive at once (the consumer fell behind)
    };
    Kind kind = Kind::kErrorFlag;
    std::size_t atFrame = 0;
    int count = 1;  // kBurst only
};

struct FakeUvcOptions {
    enum class Pace {
        kRecording,  // frames arrive at the recording's timestamps, in real time (the demo)
        kFast,       // a virtual clock jumps to the next frame whenever the consumer waits (tests)
    };
    Pace pace = Pace::kRecording;
    bool loop = true;              // start over at the end, like a camera that keeps streaming
    unsigned maxBuffers = 32;      // REQBUFS grants at most this many (uvcvideo: 32)
    bool substituteMode = false;   // S_FMT silently answers with the recording's mode, whatever was asked
    int replugAfterOpenAttempts = 2;  // after an unplug, open() fails this often before the device returns
    std::vector<FakeFault> faults;
};

// One camera mode the device lists.
struct FakeMode {
    PixelFormat format;
    int width;
    int height;
    int maxFps;
};

// The HBVCAM-4M2214HD-2 as uvcvideo lists it: MJPEG and YUYV at each size.
const std::vector<FakeMode>& hbvcamModes();

// A UVC camera behind the syscall seam that answers like the kernel's uvcvideo: QUERYCAP as
// uvcvideo, the HBVCAM modes, S_FMT snapped to the nearest mode, memfd-backed buffers that mmap
// really maps, EAGAIN when no frame is ready, readiness through poll, a few UVC controls, and
// frames from a recording (exactly its bytes) at its pace or as fast as asked, with scripted
// faults. open() accepts only devicePath().
class FakeUvcDevice final : public Syscalls {
public:
    explicit FakeUvcDevice(Recording recording, FakeUvcOptions options = {});
    ~FakeUvcDevice() override;
    FakeUvcDevice(const FakeUvcDevice&) = delete;
    FakeUvcDevice& operator=(const FakeUvcDevice&) = delete;

    int open(const std::string& path, int flags) override;
    int close(int fd) override;
    int ioctl(int fd, unsigned long request, void* arg) override;
    void* mmap(std::size_t length, int prot, int flags, int fd, off_t offset, int* error) override;
    int munmap(void* address, std::size_t length) override;
    int poll(pollfd* fds, nfds_t count, int timeoutMs) override;

    // The path open() accepts: the recording directory.
    std::string devicePath() const;
    const Recording& recording() const { return recording_; }

    // What tests look at.
    std::size_t framesProduced() const;
    int successfulOpens() const;
    int openFds() const;
    std::size_t liveMappings() const;
    // A control's current value by its v4l2-ctl name; throws std::out_of_range for unknown names.
    std::int64_t controlValue(const std::string& name) const;

private:
    struct Buffer;
    struct Control;

    int handleIoctl(int fd, unsigned long request, void* arg, std::unique_lock<std::mutex>& lock);
    int enumFormat(void* arg) const;
    int enumFrameSizes(void* arg) const;
    int enumFrameIntervals(void* arg) const;
    int setFormat(void* arg, bool apply);
    int requestBuffers(int fd, void* arg);
    int queueBuffer(void* arg);
    int dequeueBuffer(int fd, void* arg, std::unique_lock<std::mutex>& lock);
    int waitLocked(int fd, int timeoutMs, std::unique_lock<std::mutex>& lock);
    int streamOn(int fd);
    void streamOff();
    int controlIoctl(unsigned long request, void* arg);
    void freeBuffers();

    std::int64_t nowUs() const;
    std::int64_t dueUs(std::size_t position) const;
    std::int64_t frameIntervalUs() const;
    short pollEvents(int fd) const;
    void produceDueFrames();
    bool produceOne(std::int64_t timestampUs);
    bool faultAt(FakeFault::Kind kind, std::size_t frame, int* count = nullptr);
    void unplugNow();
    bool fdLive(int fd) const;

    Recording recording_;
    std::vector<std::vector<std::uint8_t>> frames_;
    FakeUvcOptions options_;
    std::vector<bool> faultUsed_;
    mutable std::mutex mutex_;

    // The device node and the file descriptors on it.
    struct OpenFile {
        int generation = 0;  // the device instance it was opened on; a re-plugged device is a new one
        int flags = 0;
    };
    std::map<int, OpenFile> fds_;
    int nextFd_ = 1000;
    int generation_ = 0;
    bool unplugged_ = false;
    int failedOpensWhileUnplugged_ = 0;
    int successfulOpens_ = 0;

    // Format and streaming state of the current generation.
    PixelFormat format_;
    int width_ = 0;
    int height_ = 0;
    int fps_ = 30;
    int ownerFd_ = -1;
    int memfd_ = -1;
    std::uint8_t* memory_ = nullptr;  // the device's own view of the buffer memory
    std::size_t memoryBytes_ = 0;
    std::vector<Buffer> buffers_;
    std::deque<unsigned> queued_;
    std::deque<unsigned> done_;
    std::map<void*, std::size_t> mappings_;
    bool streaming_ = false;
    bool stalled_ = false;
    std::uint32_t sequence_ = 0;

    // Playback.
    std::size_t produced_ = 0;   // frames produced since creation (faults count these)
    std::size_t position_ = 0;   // frames consumed from the recording timeline, loops included
    std::int64_t timelineBaseUs_ = 0;
    std::int64_t virtualNowUs_ = 0;
    std::chrono::steady_clock::time_point epoch_;

    std::vector<Control> controls_;
};

}  // namespace icewatch::v4l2
