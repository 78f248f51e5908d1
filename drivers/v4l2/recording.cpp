// Recordings: what a camera delivered, frame by frame, with the negotiated format beside it.
// recording.json is the index; frame files hold the bytes untouched. Reading validates everything
// a replay relies on, so a damaged recording fails with a message instead of replaying garbage.
#include "drivers/v4l2/recording.hpp"

#include <cstdio>
#include <fstream>
#include <sstream>

#include <linux/videodev2.h>
#include <nlohmann/json.hpp>

#include "core/common/error.hpp"
#include "core/config/json_text.hpp"

namespace icewatch::v4l2 {

namespace fs = std::filesystem;

std::string formatName(PixelFormat format) { return format == PixelFormat::kMjpeg ? "mjpeg" : "yuyv"; }

std::optional<PixelFormat> parseFormatName(const std::string& name) {
    if (name == "mjpeg") return PixelFormat::kMjpeg;
    if (name == "yuyv") return PixelFormat::kYuyv;
    return std::nullopt;
}

std::uint32_t fourcc(PixelFormat format) {
    return format == PixelFormat::kMjpeg ? V4L2_PIX_FMT_MJPEG : V4L2_PIX_FMT_YUYV;
}

std::optional<PixelFormat> fromFourcc(std::uint32_t fourccCode) {
    if (fourccCode == V4L2_PIX_FMT_MJPEG) return PixelFormat::kMjpeg;
    if (fourccCode == V4L2_PIX_FMT_YUYV) return PixelFormat::kYuyv;
    return std::nullopt;
}

std::string fourccText(std::uint32_t fourccCode) {
    std::string text;
    for (int i = 0; i < 4; ++i) {
        const char c = static_cast<char>((fourccCode >> (8 * i)) & 0xff);
        text += (c >= 32 && c < 127) ? c : '?';
    }
    return text;
}

fs::path Recording::framePath(std::size_t index) const {
    char name[32];
    std::snprintf(name, sizeof name, "%06zu.%s", index + 1, format == PixelFormat::kMjpeg ? "jpg" : "yuyv");
    return dir / name;
}

std::vector<std::uint8_t> Recording::readFrame(std::size_t index) const {
    const fs::path path = framePath(index);
    std::ifstream in(path, std::ios::binary);
    std::vector<std::uint8_t> bytes(frames.at(index).bytes);
    if (!in || !in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(bytes.size())) ||
        in.peek() != std::char_traits<char>::eof()) {
        throw Error(kExitIoErr, path.string() + ": cannot read " + std::to_string(bytes.size()) +
                                    " bytes as recording.json says (file changed or unreadable)");
    }
    return bytes;
}

namespace {

[[noreturn]] void invalid(const fs::path& file, const std::string& key, const std::string& what) {
    throw Error(kExitDataErr, file.string() + ": " + key + ": " + what);
}

const nlohmann::json& member(const nlohmann::json& object, const fs::path& file, const std::string& key) {
    const auto it = object.find(key);
    if (it == object.end()) {
        invalid(file, key, "missing");
    }
    return *it;
}

std::int64_t integer(const nlohmann::json& object, const fs::path& file, const std::string& key,
                     const std::string& path, std::int64_t min, std::int64_t max) {
    const nlohmann::json& value = member(object, file, key);
    // An unsigned above INT64_MAX would wrap in get<std::int64_t>().
    if (!value.is_number_integer() || (value.is_number_unsigned() && value.get<std::uint64_t>() > INT64_MAX)) {
        invalid(file, path, "must be an integer");
    }
    const auto v = value.get<std::int64_t>();
    if (v < min || v > max) {
        invalid(file, path, "must be between " + std::to_string(min) + " and " + std::to_string(max) + ", got " +
                                std::to_string(v));
    }
    return v;
}

std::string text(const nlohmann::json& object, const fs::path& file, const std::string& key) {
    const nlohmann::json& value = member(object, file, key);
    if (!value.is_string()) {
        invalid(file, key, "must be a string");
    }
    return value.get<std::string>();
}

}  // namespace

Recording readRecording(const fs::path& dir) {
    const fs::path file = dir / "recording.json";
    std::ifstream in(file, std::ios::binary);
    if (!in) {
        throw Error(kExitNoInput, file.string() + ": cannot read the recording index");
    }
    std::ostringstream bytes;
    bytes << in.rdbuf();
    config::JsonText document = config::parseJsonText(bytes.str());
    if (!document.error.empty()) {
        throw Error(kExitDataErr, file.string() + ": " + document.error);
    }
    const nlohmann::json root = std::move(document.value);
    if (!root.is_object()) {
        invalid(file, "(top level)", "must be a JSON object");
    }
    Recording r;
    r.dir = dir;
    r.device = text(root, file, "device");
    const std::string format = text(root, file, "pixel_format");
    const auto parsed = parseFormatName(format);
    if (!parsed) {
        invalid(file, "pixel_format", "must be mjpeg or yuyv, got \"" + format + "\"");
    }
    r.format = *parsed;
    r.width = static_cast<int>(integer(root, file, "width", "width", 2, 16384));
    r.height = static_cast<int>(integer(root, file, "height", "height", 1, 16384));
    if (r.width % 2 != 0) {
        invalid(file, "width", "must be even: a side-by-side frame holds two equal eyes");
    }
    r.fps = static_cast<int>(integer(root, file, "fps", "fps", 1, 240));
    const nlohmann::json& frames = member(root, file, "frames");
    if (!frames.is_array() || frames.empty()) {
        invalid(file, "frames", "must be a non-empty array");
    }
    const std::size_t yuyvBytes = static_cast<std::size_t>(r.width) * static_cast<std::size_t>(r.height) * 2;
    for (std::size_t i = 0; i < frames.size(); ++i) {
        const std::string key = "frames[" + std::to_string(i) + "]";
        if (!frames[i].is_object()) {
            invalid(file, key, "must be an object");
        }
        RecordedFrame frame;
        frame.timestampUs = integer(frames[i], file, "timestamp_us", key + ".timestamp_us", 0, INT64_MAX);
        frame.bytes = static_cast<std::size_t>(integer(frames[i], file, "bytes", key + ".bytes", 1, INT32_MAX));
        if (!r.frames.empty() && frame.timestampUs < r.frames.back().timestampUs) {
            invalid(file, key + ".timestamp_us", "goes backwards");
        }
        if (r.format == PixelFormat::kYuyv && frame.bytes != yuyvBytes) {
            invalid(file, key + ".bytes", "a YUYV frame of " + std::to_string(r.width) + "x" +
                                              std::to_string(r.height) + " has " + std::to_string(yuyvBytes) +
                                              " bytes, got " + std::to_string(frame.bytes));
        }
        r.frames.push_back(frame);
        const fs::path framePath = r.framePath(i);
        std::error_code ec;
        const auto size = fs::file_size(framePath, ec);
        if (ec) {
            throw Error(kExitNoInput, framePath.string() + ": frame " + std::to_string(i + 1) + " is missing");
        }
        if (size != frame.bytes) {
            throw Error(kExitDataErr, framePath.string() + ": frame " + std::to_string(i + 1) + " has " +
                                          std::to_string(size) + " bytes, recording.json says " +
                                          std::to_string(frame.bytes));
        }
    }
    return r;
}

RecordingWriter::RecordingWriter(const fs::path& dir, std::string device, PixelFormat format, int width, int height,
                                 int fps) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec || !fs::is_directory(dir)) {
        throw Error(kExitCantCreate, dir.string() + ": cannot create the recording directory");
    }
    if (fs::exists(dir / "recording.json")) {
        throw Error(kExitCantCreate, dir.string() + ": already holds a recording; choose an empty directory");
    }
    recording_.dir = dir;
    recording_.device = std::move(device);
    recording_.format = format;
    recording_.width = width;
    recording_.height = height;
    recording_.fps = fps;
}

void RecordingWriter::add(const std::uint8_t* data, std::size_t size, std::int64_t timestampUs) {
    if (!firstTimestampUs_) {
        firstTimestampUs_ = timestampUs;
    }
    RecordedFrame frame{timestampUs - *firstTimestampUs_, size};
    if (!recording_.frames.empty() && frame.timestampUs < recording_.frames.back().timestampUs) {
        frame.timestampUs = recording_.frames.back().timestampUs;  // a clock step must not make it unreadable
    }
    recording_.frames.push_back(frame);
    const fs::path path = recording_.framePath(recording_.frames.size() - 1);
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    if (!out || !out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size)) || !out.flush()) {
        throw Error(kExitCantCreate, path.string() + ": cannot write the frame");
    }
}

void RecordingWriter::finish() {
    nlohmann::json frames = nlohmann::json::array();
    for (const RecordedFrame& f : recording_.frames) {
        frames.push_back({{"timestamp_us", f.timestampUs}, {"bytes", f.bytes}});
    }
    const nlohmann::json root = {{"device", recording_.device},        {"pixel_format", formatName(recording_.format)},
                                 {"width", recording_.width},          {"height", recording_.height},
                                 {"fps", recording_.fps},              {"frames", frames}};
    const fs::path file = recording_.dir / "recording.json";
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    if (!out || !(out << root.dump(1) << "\n") || !out.flush()) {
        throw Error(kExitCantCreate, file.string() + ": cannot write the recording index");
    }
}

}  // namespace icewatch::v4l2
