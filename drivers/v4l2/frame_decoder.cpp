// Camera frames to BGR pixels, distrusting every byte.
//
// libjpeg reports trouble two ways: error_exit for what it cannot go on with, emit_message(-1)
// for damage it papers over (a truncated scan is filled with grey, "Corrupt JPEG data" skips
// bytes). Either way the frame is wrong, so both end the decode through longjmp and the frame is
// dropped. The setjmp lives in decodeJpeg(), whose locals are plain values, so jumping out of
// libjpeg skips no destructor.
#include "drivers/v4l2/frame_decoder.hpp"

#include <algorithm>
#include <csetjmp>
#include <cstdio>
#include <cstring>

#include <jpeglib.h>
#include <opencv2/imgproc.hpp>

namespace icewatch::v4l2 {

const char* dropReasonName(DropReason reason) {
    switch (reason) {
        case DropReason::kErrorFlag: return "error_flag";
        case DropReason::kShortFrame: return "short_frame";
        case DropReason::kBadIndex: return "bad_index";
        case DropReason::kNoJpegMarkers: return "no_jpeg_markers";
        case DropReason::kCorruptJpeg: return "corrupt_jpeg";
        case DropReason::kSizeMismatch: return "size_mismatch";
    }
    return "unknown";
}

std::optional<DropReason> checkFrameBytes(PixelFormat format, const std::uint8_t* data, std::size_t size, int width,
                                          int height) {
    if (format == PixelFormat::kYuyv) {
        const std::size_t expected = static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 2;
        if (size < expected) return DropReason::kShortFrame;
        if (size > expected) return DropReason::kSizeMismatch;
        return std::nullopt;
    }
    if (size < kMinJpegBytes) {
        return DropReason::kShortFrame;
    }
    if (data[0] != 0xFF || data[1] != 0xD8) {
        return DropReason::kNoJpegMarkers;
    }
    std::size_t end = size;
    while (end > 2 && data[end - 1] == 0x00) {
        --end;
    }
    if (end < 4 || data[end - 2] != 0xFF || data[end - 1] != 0xD9) {
        return DropReason::kNoJpegMarkers;
    }
    return std::nullopt;
}

namespace {

// Walks the marker segments between SOI and SOS; returns the offset of the first DHT, or of SOS
// when dht is false. npos when not found or the stream is malformed.
std::size_t findSegment(const std::uint8_t* data, std::size_t size, std::uint8_t marker) {
    std::size_t pos = 2;
    while (pos + 4 <= size) {
        if (data[pos] != 0xFF) {
            return std::string::npos;
        }
        const std::uint8_t m = data[pos + 1];
        if (m == 0xFF) {  // fill byte
            ++pos;
            continue;
        }
        if (m == marker) {
            return pos;
        }
        if (m == 0xDA) {  // SOS: headers end here
            return std::string::npos;
        }
        const std::size_t length = (std::size_t{data[pos + 2]} << 8) | data[pos + 3];
        pos += 2 + length;
    }
    return std::string::npos;
}

// The standard tables as a DHT segment, taken from libjpeg's own copy (jpeg_set_defaults installs
// them in a compressor) rather than typed in again.
std::vector<std::uint8_t> standardDhtSegment() {
    jpeg_compress_struct c{};
    jpeg_error_mgr err{};
    c.err = jpeg_std_error(&err);
    jpeg_create_compress(&c);
    c.in_color_space = JCS_YCbCr;
    c.input_components = 3;
    jpeg_set_defaults(&c);
    std::vector<std::uint8_t> tables;
    auto add = [&tables](const JHUFF_TBL* table, std::uint8_t classAndId) {
        tables.push_back(classAndId);
        std::size_t count = 0;
        for (int i = 1; i <= 16; ++i) {
            tables.push_back(table->bits[i]);
            count += table->bits[i];
        }
        tables.insert(tables.end(), table->huffval, table->huffval + count);
    };
    add(c.dc_huff_tbl_ptrs[0], 0x00);
    add(c.ac_huff_tbl_ptrs[0], 0x10);
    add(c.dc_huff_tbl_ptrs[1], 0x01);
    add(c.ac_huff_tbl_ptrs[1], 0x11);
    jpeg_destroy_compress(&c);
    const std::size_t length = tables.size() + 2;
    std::vector<std::uint8_t> segment(4 + tables.size());
    segment[0] = 0xFF;
    segment[1] = 0xC4;
    segment[2] = static_cast<std::uint8_t>(length >> 8);
    segment[3] = static_cast<std::uint8_t>(length & 0xFF);
    std::copy(tables.begin(), tables.end(), segment.begin() + 4);
    return segment;
}

}  // namespace

bool hasHuffmanTables(const std::uint8_t* data, std::size_t size) {
    return size >= 4 && findSegment(data, size, 0xC4) != std::string::npos;
}

std::vector<std::uint8_t> withStandardHuffmanTables(const std::uint8_t* data, std::size_t size) {
    static const std::vector<std::uint8_t> dht = standardDhtSegment();
    std::vector<std::uint8_t> out;
    out.reserve(size + dht.size());
    out.insert(out.end(), data, data + 2);  // SOI
    out.insert(out.end(), dht.begin(), dht.end());
    out.insert(out.end(), data + 2, data + size);
    return out;
}

std::vector<std::uint8_t> withoutHuffmanTables(const std::uint8_t* data, std::size_t size) {
    std::vector<std::uint8_t> out(data, data + std::min<std::size_t>(size, 2));
    std::size_t pos = 2;
    while (pos + 4 <= size && data[pos] == 0xFF && data[pos + 1] != 0xDA) {
        const std::size_t length = std::min(size - pos, 2 + ((std::size_t{data[pos + 2]} << 8) | data[pos + 3]));
        if (data[pos + 1] != 0xC4) {
            out.insert(out.end(), data + pos, data + pos + length);
        }
        pos += length;
    }
    if (pos < size) {
        out.insert(out.end(), data + pos, data + size);
    }
    return out;
}

struct FrameDecoder::Jpeg {
    struct ErrorManager {
        jpeg_error_mgr pub;
        std::jmp_buf jump;
        char text[JMSG_LENGTH_MAX];
    };

    static void onError(j_common_ptr info) {
        auto* e = reinterpret_cast<ErrorManager*>(info->err);
        (*info->err->format_message)(info, e->text);
        std::longjmp(e->jump, 1);
    }

    static void onMessage(j_common_ptr info, int level) {
        if (level < 0) {  // a warning: the data is damaged even if libjpeg could go on
            onError(info);
        }
    }

    Jpeg() {
        info.err = jpeg_std_error(&error.pub);
        error.pub.error_exit = onError;
        error.pub.emit_message = onMessage;
        jpeg_create_decompress(&info);
    }
    ~Jpeg() { jpeg_destroy_decompress(&info); }

    // Returns 0 on success, 1 on a libjpeg error or warning, 2 on a size mismatch.
    int decodeJpeg(const std::uint8_t* data, std::size_t size, int width, int height, cv::Mat& bgr) {
        error.text[0] = '\0';
        if (setjmp(error.jump) != 0) {
            jpeg_abort_decompress(&info);
            return 1;
        }
        jpeg_mem_src(&info, data, static_cast<unsigned long>(size));
        if (jpeg_read_header(&info, TRUE) != JPEG_HEADER_OK) {
            jpeg_abort_decompress(&info);
            std::snprintf(error.text, sizeof error.text, "no image in the JPEG stream");
            return 1;
        }
        if (info.image_width != static_cast<JDIMENSION>(width) || info.image_height != static_cast<JDIMENSION>(height)) {
            std::snprintf(error.text, sizeof error.text, "JPEG is %ux%u, the negotiated format %dx%d",
                          info.image_width, info.image_height, width, height);
            jpeg_abort_decompress(&info);
            return 2;
        }
        // Same settings as OpenCV's imdecode (libjpeg defaults: islow IDCT, fancy upsampling),
        // so a frame decodes to the same pixels here and in any tool.
        info.out_color_space = JCS_EXT_BGR;
        jpeg_start_decompress(&info);
        while (info.output_scanline < info.output_height) {
            JSAMPROW rows[16];
            const JDIMENSION first = info.output_scanline;
            const JDIMENSION count = std::min<JDIMENSION>(16, info.output_height - first);
            for (JDIMENSION i = 0; i < count; ++i) {
                rows[i] = bgr.ptr<JSAMPLE>(static_cast<int>(first + i));
            }
            jpeg_read_scanlines(&info, rows, count);
        }
        jpeg_finish_decompress(&info);
        return 0;
    }

    jpeg_decompress_struct info{};
    ErrorManager error{};
    std::string message;
};

FrameDecoder::FrameDecoder() : jpeg_(std::make_unique<Jpeg>()) {}
FrameDecoder::~FrameDecoder() = default;

const std::string& FrameDecoder::message() const { return jpeg_->message; }

std::optional<DropReason> FrameDecoder::decode(PixelFormat format, const std::uint8_t* data, std::size_t size,
                                               int width, int height, cv::Mat& bgr) {
    jpeg_->message.clear();
    if (auto bad = checkFrameBytes(format, data, size, width, height)) {
        jpeg_->message = dropReasonName(*bad);
        return bad;
    }
    bgr.create(height, width, CV_8UC3);
    if (format == PixelFormat::kYuyv) {
        const cv::Mat yuyv(height, width, CV_8UC2, const_cast<std::uint8_t*>(data));
        cv::cvtColor(yuyv, bgr, cv::COLOR_YUV2BGR_YUYV);
        return std::nullopt;
    }
    if (!hasHuffmanTables(data, size)) {
        patched_ = withStandardHuffmanTables(data, size);
        data = patched_.data();
        size = patched_.size();
    }
    const int result = jpeg_->decodeJpeg(data, size, width, height, bgr);
    jpeg_->message = jpeg_->error.text;
    if (result == 1) return DropReason::kCorruptJpeg;
    if (result == 2) return DropReason::kSizeMismatch;
    return std::nullopt;
}

}  // namespace icewatch::v4l2
