#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include <linux/videodev2.h>

#include "drivers/v4l2/syscalls.hpp"

namespace icewatch::v4l2 {

// Typed view of VIDIOC_QUERYCAP's answer. Per-node capabilities (device_caps) decide when the
// driver provides them: `capabilities` describes the whole physical device.
struct Capability : v4l2_capability {
    std::uint32_t nodeCaps() const { return (capabilities & V4L2_CAP_DEVICE_CAPS) != 0 ? device_caps : capabilities; }
    bool isVideoCapture() const { return (nodeCaps() & V4L2_CAP_VIDEO_CAPTURE) != 0; }
    bool hasStreaming() const { return (nodeCaps() & V4L2_CAP_STREAMING) != 0; }
    std::string driverName() const;
    std::string cardName() const;
    std::string busInfo() const;
};

struct FormatDescription {
    std::uint32_t fourcc = 0;
    std::string description;
    bool compressed = false;
};

struct FrameSize {
    int width = 0;
    int height = 0;
};

struct FrameInterval {
    std::uint32_t numerator = 0;
    std::uint32_t denominator = 0;
};

struct ControlInfo {
    std::uint32_t id = 0;
    std::string name;  // as v4l2-ctl prints it: "exposure_time_absolute"
    std::string label; // as the driver names it: "Exposure Time, Absolute"
    std::uint32_t type = 0;
    std::int32_t minimum = 0;
    std::int32_t maximum = 0;
    std::int32_t step = 0;
    std::int32_t defaultValue = 0;
    std::int32_t value = 0;
    std::uint32_t flags = 0;
    std::vector<std::pair<std::int32_t, std::string>> menu;  // menu controls only
};

// v4l2-ctl's spelling of a control name: lower case, runs of other characters become one '_'.
std::string controlVariableName(const std::string& label);
// "integer", "boolean", "menu", ... as v4l2-ctl prints the type.
std::string controlTypeName(std::uint32_t type);

// One V4L2 video node: owns its file descriptor and speaks to it only through the syscall seam.
// Every call returns 0 (or a count) on success and -errno on failure, without logging: the caller
// knows what the failure means and whether to say so.
class V4l2Device {
public:
    explicit V4l2Device(Syscalls& syscalls) : syscalls_(syscalls) {}
    ~V4l2Device() { close(); }
    V4l2Device(const V4l2Device&) = delete;
    V4l2Device& operator=(const V4l2Device&) = delete;

    // Opens non-blocking (DQBUF then says EAGAIN instead of waiting; poll() does the waiting).
    int open(const std::string& path);
    void close();
    bool isOpen() const { return fd_ >= 0; }

    int queryCapability(Capability& capability);
    int enumFormats(std::vector<FormatDescription>& formats);
    int enumFrameSizes(std::uint32_t fourccCode, std::vector<FrameSize>& sizes);
    int enumFrameIntervals(std::uint32_t fourccCode, const FrameSize& size, std::vector<FrameInterval>& intervals);
    int getFormat(v4l2_pix_format& format);
    // Asks for format and leaves in it what the driver chose.
    int setFormat(v4l2_pix_format& format);
    // Asks for fps and leaves in interval the frame interval the driver chose.
    int setFrameRate(int fps, FrameInterval& interval);
    // Asks for count buffers and leaves in it how many the driver granted.
    int requestBuffers(unsigned& count);
    int queryBuffer(unsigned index, v4l2_buffer& buffer);
    int queueBuffer(unsigned index);
    // -EAGAIN when nothing is ready.
    int dequeueBuffer(v4l2_buffer& buffer);
    int streamOn();
    int streamOff();
    // Waits until a buffer can be dequeued: the poll() result (0 = timeout) with its revents.
    int waitReadable(int timeoutMs, short& revents);
    int queryControls(std::vector<ControlInfo>& controls);
    int setControl(std::uint32_t id, std::int32_t value);
    int getControl(std::uint32_t id, std::int32_t& value);
    void* map(std::size_t length, off_t offset, int& error);
    int unmap(void* address, std::size_t length);

private:
    // The one place ioctls are made; an ioctl interrupted by a signal is simply repeated.
    int ioctl(unsigned long request, void* arg);

    Syscalls& syscalls_;
    int fd_ = -1;
};

}  // namespace icewatch::v4l2
