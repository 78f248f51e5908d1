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

// "fake:DIR[?OPTIONS]" replays the recording in DIR through a FakeUvcDevice (the real driver code
// runs on top of it; fakeOptions choose pace and faults, options in the string override them); anything else is a real device through libc:
// /dev/videoN or a stable /dev/v4l/by-id/... link, which follows the camera across re-plugs.
// Throws Error when the recording cannot be read.
DeviceSeam makeDeviceSeam(const std::string& device, const FakeUvcOptions& fakeOptions = {});

// True for "fake:DIR".
bool isFakeDevice(const std::string& device);

// fake:DIR?OPTION=VALUE&... : the recording directory and the fake camera's behaviour, so the
// shipped programs can be run through camera faults. Options (frames count from 0 since the
// device was made, comma lists allowed): unplug_at, stall_at, truncate (a JPEG cut in half),
// error_at (V4L2_BUF_FLAG_ERROR), zero_at (bytesused 0), eintr_at, bad_index_at,
// burst_at=FRAME[:COUNT]; pace=fast|recording, loop=0|1, replug_after=N (failed opens after an
// unplug). Throws Error(kExitConfig) naming an unknown option or a bad value.
struct FakeDevice {
    std::string directory;
    FakeUvcOptions options;  // the defaults where the string says nothing
};
FakeDevice parseFakeDevice(const std::string& device);

}  // namespace icewatch::v4l2
