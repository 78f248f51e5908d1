// Picks the kernel or the fake camera for a configured device string.
#include "drivers/v4l2/device_seam.hpp"

namespace icewatch::v4l2 {

namespace {
constexpr std::string_view kFakePrefix = "fake:";
}

bool isFakeDevice(const std::string& device) { return device.rfind(kFakePrefix, 0) == 0; }

DeviceSeam makeDeviceSeam(const std::string& device, const FakeUvcOptions& fakeOptions) {
    DeviceSeam seam;
    if (isFakeDevice(device)) {
        auto fake = std::make_unique<FakeUvcDevice>(readRecording(device.substr(kFakePrefix.size())), fakeOptions);
        seam.path = fake->devicePath();
        seam.fake = fake.get();
        seam.syscalls = std::move(fake);
    } else {
        seam.syscalls = std::make_unique<LibcSyscalls>();
        seam.path = device;
    }
    return seam;
}

}  // namespace icewatch::v4l2
