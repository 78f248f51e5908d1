#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace icewatch::v4l2 {

// The two pixel formats the HBVCAM offers.
enum class PixelFormat { kMjpeg, kYuyv };

// "mjpeg" / "yuyv", as in the configuration and on the command line.
std::string formatName(PixelFormat format);
std::optional<PixelFormat> parseFormatName(const std::string& name);
std::uint32_t fourcc(PixelFormat format);
std::optional<PixelFormat> fromFourcc(std::uint32_t fourccCode);
// "MJPG" from V4L2_PIX_FMT_MJPEG: how v4l2-ctl and the kernel spell a FourCC.
std::string fourccText(std::uint32_t fourccCode);

struct RecordedFrame {
    std::int64_t timestampUs = 0;  // since the first frame
    std::size_t bytes = 0;
};

// A recording: recording.json plus the frames exactly as the device delivered them
// (000001.jpg for MJPEG, 000001.yuyv raw), so a replay is byte-for-byte what the camera sent.
struct Recording {
    std::filesystem::path dir;
    std::string device;  // what it was recorded from
    PixelFormat format = PixelFormat::kMjpeg;
    int width = 0;
    int height = 0;
    int fps = 0;
    std::vector<RecordedFrame> frames;

    // index counts from 0; the file names count from 1.
    std::filesystem::path framePath(std::size_t index) const;
    // Throws Error (74) when the file cannot be read or its size differs from recording.json.
    std::vector<std::uint8_t> readFrame(std::size_t index) const;
};

// Reads and validates recording.json and checks every frame file exists with its recorded size.
// Throws Error naming the file, key and frame: 66 when something is missing, 65 when it is wrong.
Recording readRecording(const std::filesystem::path& dir);

// Writes a recording frame by frame; recording.json is written by finish(), so a recording cut
// short by an error is not mistaken for a complete one. Throws Error (73) on write failures.
class RecordingWriter {
public:
    RecordingWriter(const std::filesystem::path& dir, std::string device, PixelFormat format, int width, int height,
                    int fps);

    void add(const std::uint8_t* data, std::size_t size, std::int64_t timestampUs);
    void finish();
    const Recording& recording() const { return recording_; }

private:
    Recording recording_;
    std::optional<std::int64_t> firstTimestampUs_;
};

}  // namespace icewatch::v4l2
