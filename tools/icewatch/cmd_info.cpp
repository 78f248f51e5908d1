// icewatch info: what a V4L2 camera offers (capabilities, formats, frame sizes and intervals,
// controls), asked the same way the capture code asks, through the same seam.
#include <cstring>
#include <iostream>

#include <nlohmann/json.hpp>

#include "core/common/error.hpp"
#include "drivers/v4l2/device_seam.hpp"
#include "drivers/v4l2/recording.hpp"
#include "drivers/v4l2/v4l2_device.hpp"
#include "tools/icewatch/command.hpp"

namespace icewatch::cli {

namespace {

struct InfoOptions {
    std::string device;
    bool json = false;
};

void check(int ret, const std::string& what, const std::string& device) {
    if (ret < 0) {
        throw Error(kExitIoErr, device + ": " + what + " failed: " + std::strerror(-ret));
    }
}

nlohmann::json describe(v4l2::V4l2Device& device, const std::string& path) {
    v4l2::Capability cap;
    const int ret = device.queryCapability(cap);
    if (ret == -ENOTTY || ret == -EINVAL) {
        throw Error(kExitUnavailable, path + " is not a V4L2 device");
    }
    check(ret, "VIDIOC_QUERYCAP", path);
    nlohmann::json info = {{"device", path},
                           {"driver", cap.driverName()},
                           {"card", cap.cardName()},
                           {"bus_info", cap.busInfo()},
                           {"version", std::to_string(cap.version >> 16) + "." + std::to_string((cap.version >> 8) & 0xff) +
                                           "." + std::to_string(cap.version & 0xff)},
                           {"video_capture", cap.isVideoCapture()},
                           {"streaming", cap.hasStreaming()}};
    nlohmann::json formats = nlohmann::json::array();
    if (cap.isVideoCapture()) {
        std::vector<v4l2::FormatDescription> list;
        check(device.enumFormats(list), "VIDIOC_ENUM_FMT", path);
        for (const v4l2::FormatDescription& f : list) {
            nlohmann::json sizes = nlohmann::json::array();
            std::vector<v4l2::FrameSize> frameSizes;
            check(device.enumFrameSizes(f.fourcc, frameSizes), "VIDIOC_ENUM_FRAMESIZES", path);
            for (const v4l2::FrameSize& s : frameSizes) {
                std::vector<v4l2::FrameInterval> intervals;
                check(device.enumFrameIntervals(f.fourcc, s, intervals), "VIDIOC_ENUM_FRAMEINTERVALS", path);
                nlohmann::json fps = nlohmann::json::array();
                for (const v4l2::FrameInterval& i : intervals) {
                    fps.push_back(i.numerator == 0 ? 0.0 : double(i.denominator) / i.numerator);
                }
                sizes.push_back({{"width", s.width}, {"height", s.height}, {"fps", fps}});
            }
            formats.push_back({{"fourcc", v4l2::fourccText(f.fourcc)},
                               {"description", f.description},
                               {"compressed", f.compressed},
                               {"sizes", sizes}});
        }
    }
    info["formats"] = formats;
    nlohmann::json controls = nlohmann::json::array();
    std::vector<v4l2::ControlInfo> list;
    check(device.queryControls(list), "VIDIOC_QUERYCTRL", path);
    for (const v4l2::ControlInfo& c : list) {
        nlohmann::json control = {{"name", c.name},       {"label", c.label},       {"type", v4l2::controlTypeName(c.type)},
                                  {"min", c.minimum},     {"max", c.maximum},       {"step", c.step},
                                  {"default", c.defaultValue}, {"value", c.value},
                                  {"inactive", (c.flags & V4L2_CTRL_FLAG_INACTIVE) != 0}};
        if (!c.menu.empty()) {
            nlohmann::json menu = nlohmann::json::object();
            for (const auto& [index, name] : c.menu) menu[std::to_string(index)] = name;
            control["menu"] = menu;
        }
        controls.push_back(control);
    }
    info["controls"] = controls;
    return info;
}

void printText(const nlohmann::json& info) {
    std::cout << info["device"].get<std::string>() << ": " << info["card"].get<std::string>() << " ("
              << info["driver"].get<std::string>() << " " << info["version"].get<std::string>() << ", "
              << info["bus_info"].get<std::string>() << ")\n";
    std::cout << "  video capture: " << (info["video_capture"].get<bool>() ? "yes" : "no")
              << ", streaming: " << (info["streaming"].get<bool>() ? "yes" : "no") << "\n";
    for (const auto& f : info["formats"]) {
        std::cout << "  " << f["fourcc"].get<std::string>() << " (" << f["description"].get<std::string>() << ")\n";
        for (const auto& s : f["sizes"]) {
            std::cout << "    " << s["width"] << "x" << s["height"] << " fps:";
            for (const auto& fps : s["fps"]) std::cout << " " << fps.get<double>();
            std::cout << "\n";
        }
    }
    std::cout << "  controls:\n";
    for (const auto& c : info["controls"]) {
        std::cout << "    " << c["name"].get<std::string>() << " (" << c["type"].get<std::string>() << ") min="
                  << c["min"] << " max=" << c["max"] << " step=" << c["step"] << " default=" << c["default"]
                  << " value=" << c["value"] << (c["inactive"].get<bool>() ? " inactive" : "") << "\n";
        if (c.contains("menu")) {
            for (const auto& [index, name] : c["menu"].items()) {
                std::cout << "      " << index << ": " << name.get<std::string>() << "\n";
            }
        }
    }
}

int runInfo(const InfoOptions& o) {
    v4l2::DeviceSeam seam = v4l2::makeDeviceSeam(o.device);
    v4l2::V4l2Device device(*seam.syscalls);
    const int ret = device.open(seam.path);
    if (ret < 0) {
        throw Error(ret == -ENOENT || ret == -ENODEV ? kExitUnavailable : kExitNoInput,
                    "cannot open " + o.device + ": " + std::strerror(-ret));
    }
    const nlohmann::json info = describe(device, o.device);
    if (o.json) {
        std::cout << info.dump() << "\n";
    } else {
        printText(info);
    }
    return 0;
}

}  // namespace

void addInfoCommand(CLI::App& app, const GlobalOptions& /*global*/, RunFunction& run) {
    CLI::App* cmd = app.add_subcommand("info", "list a camera's capabilities, formats, frame sizes, intervals, controls");
    auto o = std::make_shared<InfoOptions>();
    cmd->add_option("--device", o->device, "/dev/videoN, /dev/v4l/by-id/..., or fake:DIR (a recording)")->required();
    cmd->add_flag("--json", o->json, "print one JSON object");
    cmd->callback([&run, o] { run = [o] { return runInfo(*o); }; });
}

}  // namespace icewatch::cli
