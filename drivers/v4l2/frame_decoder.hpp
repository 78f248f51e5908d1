#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "drivers/v4l2/recording.hpp"

namespace icewatch::v4l2 {

// Why a frame from the driver was dropped instead of passed on.
enum class DropReason {
    kErrorFlag,     // V4L2_BUF_FLAG_ERROR: the driver knows the payload is damaged
    kShortFrame,    // bytesused below what the format needs (0, or a partial YUYV frame)
    kBadIndex,      // a buffer index we never queued, or one we already hold
    kNoJpegMarkers, // MJPEG without SOI (FF D8) at the start or EOI (FF D9) at the end
    kCorruptJpeg,   // libjpeg reported an error or a warning while decoding
    kSizeMismatch,  // the frame's own size differs from the negotiated format
};
inline constexpr std::size_t kDropReasonCount = 6;
// "error_flag", "short_frame", ... (JSON keys, log lines).
const char* dropReasonName(DropReason reason);

// The smallest MJPEG frame taken seriously: SOI, quantisation and frame headers, SOS and EOI
// alone take more than this.
inline constexpr std::size_t kMinJpegBytes = 128;

// The cheap checks made on the bytes before they are decoded (buffer flags and indices are the
// capture's business). YUYV must fill the frame exactly (less: short, more: another size); MJPEG must start with SOI and end with
// EOI, trailing zero padding (some UVC cameras send it) aside.
std::optional<DropReason> checkFrameBytes(PixelFormat format, const std::uint8_t* data, std::size_t size, int width,
                                          int height);

// True when the JPEG defines Huffman tables (a DHT segment) before its first scan.
bool hasHuffmanTables(const std::uint8_t* data, std::size_t size);
// The JPEG with the standard Huffman tables (ITU-T T.81 K.3) inserted after SOI: UVC MJPEG may
// leave them out because they are implied (the UVC payload spec; ffmpeg and mjpg-streamer do the
// same). Expects data to start with SOI.
std::vector<std::uint8_t> withStandardHuffmanTables(const std::uint8_t* data, std::size_t size);
// The reverse: a JPEG with its DHT segments removed, as a UVC camera sends MJPEG (recordings of
// synthetic scenes, tests). Only meaningful for JPEGs coded with the standard tables.
std::vector<std::uint8_t> withoutHuffmanTables(const std::uint8_t* data, std::size_t size);

// Decodes camera frames to BGR: MJPEG through libjpeg (libjpeg-turbo on Debian), YUYV through
// OpenCV. A JPEG that raises any libjpeg warning ("Corrupt JPEG data", "Premature end") is
// dropped, not passed on with grey blocks. The output Mat is reallocated only when the size
// changes. One decoder per thread.
class FrameDecoder {
public:
    FrameDecoder();
    ~FrameDecoder();
    FrameDecoder(const FrameDecoder&) = delete;
    FrameDecoder& operator=(const FrameDecoder&) = delete;

    // Decodes a frame of width x height into bgr (CV_8UC3). On failure returns why and leaves
    // bgr's content undefined; message() then says what libjpeg said.
    std::optional<DropReason> decode(PixelFormat format, const std::uint8_t* data, std::size_t size, int width,
                                     int height, cv::Mat& bgr);
    const std::string& message() const;

private:
    struct Jpeg;
    std::unique_ptr<Jpeg> jpeg_;
    std::vector<std::uint8_t> patched_;  // frames lacking Huffman tables, with them inserted
};

}  // namespace icewatch::v4l2
