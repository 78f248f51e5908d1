// Picks the kernel or the fake camera for a configured device string.
#include "drivers/v4l2/device_seam.hpp"

#include <charconv>
#include <map>

#include "core/common/error.hpp"

namespace icewatch::v4l2 {

namespace {
constexpr std::string_view kFakePrefix = "fake:";

const std::map<std::string, FakeFault::Kind>& faultOptions() {
    static const std::map<std::string, FakeFault::Kind> kOptions{
        {"unplug_at", FakeFault::Kind::kUnplug},         {"stall_at", FakeFault::Kind::kStall},
        {"truncate", FakeFault::Kind::kTruncatedJpeg},   {"error_at", FakeFault::Kind::kErrorFlag},
        {"zero_at", FakeFault::Kind::kZeroBytes},        {"eintr_at", FakeFault::Kind::kInterrupt},
        {"bad_index_at", FakeFault::Kind::kUnknownIndex}, {"burst_at", FakeFault::Kind::kBurst},
    };
    return kOptions;
}

[[noreturn]] void failOption(const std::string& device, const std::string& what) {
    throw Error(kExitConfig, "camera device " + device + ": " + what);
}

int numberIn(const std::string& device, const std::string& key, const std::string& text, int min, int max) {
    int value = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (ec != std::errc() || end != text.data() + text.size() || value < min || value > max) {
        failOption(device, key + ": \"" + text + "\" is not a whole number from " + std::to_string(min) + " to " +
                               std::to_string(max));
    }
    return value;
}
}  // namespace

FakeDevice parseFakeDevice(const std::string& device) {
    FakeDevice fake;
    const std::string rest = device.substr(kFakePrefix.size());
    const std::size_t query = rest.find('?');
    fake.directory = rest.substr(0, query);
    if (fake.directory.empty()) failOption(device, "no recording directory after fake:");
    if (query == std::string::npos) return fake;
    std::size_t start = query + 1;
    while (start <= rest.size()) {
        const std::size_t end = std::min(rest.find('&', start), rest.size());
        const std::string pair = rest.substr(start, end - start);
        start = end + 1;
        if (pair.empty()) continue;
        const std::size_t eq = pair.find('=');
        const std::string key = pair.substr(0, eq), value = eq == std::string::npos ? "" : pair.substr(eq + 1);
        if (key == "pace") {
            if (value != "fast" && value != "recording") failOption(device, "pace: must be fast or recording");
            fake.options.pace = value == "fast" ? FakeUvcOptions::Pace::kFast : FakeUvcOptions::Pace::kRecording;
        } else if (key == "loop") {
            fake.options.loop = numberIn(device, key, value, 0, 1) == 1;
        } else if (key == "replug_after") {
            fake.options.replugAfterOpenAttempts = numberIn(device, key, value, 0, 1000000);
        } else if (const auto kind = faultOptions().find(key); kind != faultOptions().end()) {
            // A comma list of frames; burst_at takes FRAME:COUNT.
            std::size_t from = 0;
            while (from <= value.size()) {
                const std::size_t comma = std::min(value.find(',', from), value.size());
                std::string item = value.substr(from, comma - from);
                from = comma + 1;
                FakeFault fault{kind->second, 0, 1};
                if (kind->second == FakeFault::Kind::kBurst) {
                    const std::size_t colon = item.find(':');
                    if (colon != std::string::npos) {
                        fault.count = numberIn(device, key, item.substr(colon + 1), 1, 64);
                        item = item.substr(0, colon);
                    }
                }
                fault.atFrame = static_cast<std::size_t>(numberIn(device, key, item, 0, 100000000));
                fake.options.faults.push_back(fault);
            }
        } else {
            std::string known = "pace, loop, replug_after";
            for (const auto& [name, k] : faultOptions()) known += ", " + name;
            failOption(device, "unknown option \"" + key + "\" (" + known + ")");
        }
    }
    return fake;
}

bool isFakeDevice(const std::string& device) { return device.rfind(kFakePrefix, 0) == 0; }

DeviceSeam makeDeviceSeam(const std::string& device, const FakeUvcOptions& fakeOptions) {
    DeviceSeam seam;
    if (isFakeDevice(device)) {
        FakeDevice parsed = parseFakeDevice(device);
        FakeUvcOptions options = fakeOptions;
        if (device.find('?') != std::string::npos) {
            // Options in the device string win over the caller's defaults; faults add up.
            options.pace = parsed.options.pace;
            options.loop = parsed.options.loop;
            options.replugAfterOpenAttempts = parsed.options.replugAfterOpenAttempts;
            options.faults.insert(options.faults.end(), parsed.options.faults.begin(), parsed.options.faults.end());
        }
        auto fake = std::make_unique<FakeUvcDevice>(readRecording(parsed.directory), options);
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
