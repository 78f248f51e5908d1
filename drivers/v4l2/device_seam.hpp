#pragma once

#include <memory>
#include <string>

#include "drivers/v4l2/fake_uvc_device.hpp"
#include "drivers/v4l2/syscalls.hpp"

namespace icewatch::v4l2 {

// The syscall seam a configured camera.device runs on, and the path to open through it.
struct DeviceSeam {
    std::unique_ptr<Syscalls> syscalls;
    std::string path;
    FakeUvcDevice* fake = nullptr;  // set when replaying a recording
};

// "fake:DIR" replays the recording in DIR through a FakeUvcDevice (the real driver code runs on
// top of it; fakeOptions choose pace and faults); anything else is a real device through libc:
// /dev/videoN or a stable /dev/v4l/by-id/... link, which follows the camera across re-plugs.
// Throws Error when the recording cannot be read.
DeviceSeam makeDeviceSeam(const std::string& device, const FakeUvcOptions& fakeOptions = {});

// True for "fake:DIR".
bool isFakeDevice(const std::string& device);

}  // namespace icewatch::v4l2
