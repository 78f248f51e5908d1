// The V4L2 video node: one low-level ioctl() returning -errno, a typed wrapper per ioctl, typed
// views of the kernel structs. No policy lives here (no retries beyond EINTR, no logging): the
// capture code above decides what an error means.
#include "drivers/v4l2/v4l2_device.hpp"

#include <cctype>
#include <cerrno>
#include <cstring>

#include <fcntl.h>
#include <sys/mman.h>

namespace icewatch::v4l2 {

namespace {

std::string fixedString(const std::uint8_t* bytes, std::size_t size) {
    return std::string(reinterpret_cast<const char*>(bytes), strnlen(reinterpret_cast<const char*>(bytes), size));
}

}  // namespace

std::string Capability::driverName() const { return fixedString(driver, sizeof driver); }
std::string Capability::cardName() const { return fixedString(card, sizeof card); }
std::string Capability::busInfo() const { return fixedString(bus_info, sizeof bus_info); }

std::string controlVariableName(const std::string& label) {
    // v4l2-ctl's name2var(): the names users copy into configuration files.
    std::string name;
    bool underscore = false;
    for (char c : label) {
        if (std::isalnum(static_cast<unsigned char>(c))) {
            if (underscore) name += '_';
            underscore = false;
            name += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
        } else if (!name.empty()) {
            underscore = true;
        }
    }
    return name;
}

std::string controlTypeName(std::uint32_t type) {
    switch (type) {
        case V4L2_CTRL_TYPE_INTEGER: return "int";
        case V4L2_CTRL_TYPE_BOOLEAN: return "bool";
        case V4L2_CTRL_TYPE_MENU: return "menu";
        case V4L2_CTRL_TYPE_INTEGER_MENU: return "intmenu";
        case V4L2_CTRL_TYPE_BUTTON: return "button";
        case V4L2_CTRL_TYPE_INTEGER64: return "int64";
        case V4L2_CTRL_TYPE_BITMASK: return "bitmask";
        default: return "type" + std::to_string(type);
    }
}

int V4l2Device::open(const std::string& path) {
    close();
    const int fd = syscalls_.open(path, O_RDWR | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) {
        return fd;
    }
    fd_ = fd;
    return 0;
}

void V4l2Device::close() {
    if (fd_ >= 0) {
        syscalls_.close(fd_);
        fd_ = -1;
    }
}

int V4l2Device::ioctl(unsigned long request, void* arg) {
    if (fd_ < 0) {
        return -EBADF;
    }
    int result;
    do {
        result = syscalls_.ioctl(fd_, request, arg);
    } while (result == -EINTR);
    return result;
}

int V4l2Device::queryCapability(Capability& capability) {
    std::memset(&capability, 0, sizeof capability);
    return ioctl(VIDIOC_QUERYCAP, static_cast<v4l2_capability*>(&capability));
}

int V4l2Device::enumFormats(std::vector<FormatDescription>& formats) {
    formats.clear();
    for (std::uint32_t index = 0;; ++index) {
        v4l2_fmtdesc desc{};
        desc.index = index;
        desc.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        const int ret = ioctl(VIDIOC_ENUM_FMT, &desc);
        if (ret == -EINVAL) {
            return 0;  // the end of the list
        }
        if (ret < 0) {
            return ret;
        }
        formats.push_back({desc.pixelformat, fixedString(desc.description, sizeof desc.description),
                           (desc.flags & V4L2_FMT_FLAG_COMPRESSED) != 0});
    }
}

int V4l2Device::enumFrameSizes(std::uint32_t fourccCode, std::vector<FrameSize>& sizes) {
    sizes.clear();
    for (std::uint32_t index = 0;; ++index) {
        v4l2_frmsizeenum size{};
        size.index = index;
        size.pixel_format = fourccCode;
        const int ret = ioctl(VIDIOC_ENUM_FRAMESIZES, &size);
        if (ret == -EINVAL) {
            return 0;
        }
        if (ret < 0) {
            return ret;
        }
        if (size.type == V4L2_FRMSIZE_TYPE_DISCRETE) {
            sizes.push_back({static_cast<int>(size.discrete.width), static_cast<int>(size.discrete.height)});
        } else {
            // Stepwise/continuous: UVC never does this; list the corners so nothing is hidden.
            sizes.push_back({static_cast<int>(size.stepwise.min_width), static_cast<int>(size.stepwise.min_height)});
            sizes.push_back({static_cast<int>(size.stepwise.max_width), static_cast<int>(size.stepwise.max_height)});
            return 0;
        }
    }
}

int V4l2Device::enumFrameIntervals(std::uint32_t fourccCode, const FrameSize& frameSize,
                                   std::vector<FrameInterval>& intervals) {
    intervals.clear();
    for (std::uint32_t index = 0;; ++index) {
        v4l2_frmivalenum interval{};
        interval.index = index;
        interval.pixel_format = fourccCode;
        interval.width = static_cast<std::uint32_t>(frameSize.width);
        interval.height = static_cast<std::uint32_t>(frameSize.height);
        const int ret = ioctl(VIDIOC_ENUM_FRAMEINTERVALS, &interval);
        if (ret == -EINVAL) {
            return 0;
        }
        if (ret < 0) {
            return ret;
        }
        if (interval.type == V4L2_FRMIVAL_TYPE_DISCRETE) {
            intervals.push_back({interval.discrete.numerator, interval.discrete.denominator});
        } else {
            intervals.push_back({interval.stepwise.min.numerator, interval.stepwise.min.denominator});
            intervals.push_back({interval.stepwise.max.numerator, interval.stepwise.max.denominator});
            return 0;
        }
    }
}

int V4l2Device::getFormat(v4l2_pix_format& format) {
    v4l2_format f{};
    f.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    const int ret = ioctl(VIDIOC_G_FMT, &f);
    if (ret == 0) {
        format = f.fmt.pix;
    }
    return ret;
}

int V4l2Device::setFormat(v4l2_pix_format& format) {
    v4l2_format f{};
    f.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    f.fmt.pix = format;
    const int ret = ioctl(VIDIOC_S_FMT, &f);
    if (ret == 0) {
        format = f.fmt.pix;
    }
    return ret;
}

int V4l2Device::setFrameRate(int fps, FrameInterval& interval) {
    v4l2_streamparm parm{};
    parm.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    parm.parm.capture.timeperframe = {1, static_cast<std::uint32_t>(fps)};
    const int ret = ioctl(VIDIOC_S_PARM, &parm);
    if (ret == 0) {
        interval = {parm.parm.capture.timeperframe.numerator, parm.parm.capture.timeperframe.denominator};
    }
    return ret;
}

int V4l2Device::requestBuffers(unsigned& count) {
    v4l2_requestbuffers req{};
    req.count = count;
    req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    req.memory = V4L2_MEMORY_MMAP;
    const int ret = ioctl(VIDIOC_REQBUFS, &req);
    if (ret == 0) {
        count = req.count;
    }
    return ret;
}

int V4l2Device::queryBuffer(unsigned index, v4l2_buffer& buffer) {
    std::memset(&buffer, 0, sizeof buffer);
    buffer.index = index;
    buffer.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    buffer.memory = V4L2_MEMORY_MMAP;
    return ioctl(VIDIOC_QUERYBUF, &buffer);
}

int V4l2Device::queueBuffer(unsigned index) {
    v4l2_buffer buffer{};
    buffer.index = index;
    buffer.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    buffer.memory = V4L2_MEMORY_MMAP;
    return ioctl(VIDIOC_QBUF, &buffer);
}

int V4l2Device::dequeueBuffer(v4l2_buffer& buffer) {
    std::memset(&buffer, 0, sizeof buffer);
    buffer.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    buffer.memory = V4L2_MEMORY_MMAP;
    return ioctl(VIDIOC_DQBUF, &buffer);
}

int V4l2Device::streamOn() {
    int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    return ioctl(VIDIOC_STREAMON, &type);
}

int V4l2Device::streamOff() {
    int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    return ioctl(VIDIOC_STREAMOFF, &type);
}

int V4l2Device::waitReadable(int timeoutMs, short& revents) {
    pollfd fd{fd_, POLLIN, 0};
    const int ret = syscalls_.poll(&fd, 1, timeoutMs);
    revents = ret > 0 ? fd.revents : 0;
    return ret;
}

int V4l2Device::queryControls(std::vector<ControlInfo>& controls) {
    controls.clear();
    v4l2_queryctrl query{};
    query.id = V4L2_CTRL_FLAG_NEXT_CTRL;
    for (;;) {
        const int ret = ioctl(VIDIOC_QUERYCTRL, &query);
        if (ret == -EINVAL) {
            return 0;  // past the last control
        }
        if (ret < 0) {
            return ret;
        }
        const std::uint32_t id = query.id;
        if ((query.flags & V4L2_CTRL_FLAG_DISABLED) == 0 && query.type != V4L2_CTRL_TYPE_CTRL_CLASS) {
            ControlInfo info;
            info.id = id;
            info.label = fixedString(query.name, sizeof query.name);
            info.name = controlVariableName(info.label);
            info.type = query.type;
            info.minimum = query.minimum;
            info.maximum = query.maximum;
            info.step = query.step;
            info.defaultValue = query.default_value;
            info.flags = query.flags;
            if ((query.flags & V4L2_CTRL_FLAG_WRITE_ONLY) == 0) {
                getControl(id, info.value);
            }
            if (query.type == V4L2_CTRL_TYPE_MENU) {
                for (std::int32_t item = query.minimum; item <= query.maximum; ++item) {
                    v4l2_querymenu menu{};
                    menu.id = id;
                    menu.index = static_cast<std::uint32_t>(item);
                    if (ioctl(VIDIOC_QUERYMENU, &menu) == 0) {  // gaps are items the device lacks
                        info.menu.emplace_back(item, fixedString(menu.name, sizeof menu.name));
                    }
                }
            }
            controls.push_back(std::move(info));
        }
        query = v4l2_queryctrl{};
        query.id = id | V4L2_CTRL_FLAG_NEXT_CTRL;
    }
}

int V4l2Device::setControl(std::uint32_t id, std::int32_t value) {
    v4l2_control control{id, value};
    return ioctl(VIDIOC_S_CTRL, &control);
}

int V4l2Device::getControl(std::uint32_t id, std::int32_t& value) {
    v4l2_control control{id, 0};
    const int ret = ioctl(VIDIOC_G_CTRL, &control);
    if (ret == 0) {
        value = control.value;
    }
    return ret;
}

void* V4l2Device::map(std::size_t length, off_t offset, int& error) {
    return syscalls_.mmap(length, PROT_READ | PROT_WRITE, MAP_SHARED, fd_, offset, &error);
}

int V4l2Device::unmap(void* address, std::size_t length) { return syscalls_.munmap(address, length); }

}  // namespace icewatch::v4l2
