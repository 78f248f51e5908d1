// make_demo_recording DIR: writes the bundled demo recording (tools/demo/recording) from the
// synthetic scene in demo_scene.hpp. Frames are MJPEG without Huffman tables, as UVC cameras send
// them, so the demo exercises the decoder's table insertion too.
#include <filesystem>
#include <iostream>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "core/common/side_by_side.hpp"
#include "drivers/v4l2/recording.hpp"
#include "tools/demo/demo_scene.hpp"

namespace {

// Removes every DHT segment before the first scan (the tables are the standard ones).
std::vector<std::uint8_t> withoutHuffmanTables(const std::vector<std::uint8_t>& jpeg) {
    std::vector<std::uint8_t> out(jpeg.begin(), jpeg.begin() + 2);
    std::size_t pos = 2;
    while (pos + 4 <= jpeg.size() && jpeg[pos] == 0xFF && jpeg[pos + 1] != 0xDA) {
        const std::size_t length = (std::size_t{jpeg[pos + 2]} << 8) | jpeg[pos + 3];
        if (jpeg[pos + 1] != 0xC4) {
            out.insert(out.end(), jpeg.begin() + static_cast<long>(pos), jpeg.begin() + static_cast<long>(pos + 2 + length));
        }
        pos += 2 + length;
    }
    out.insert(out.end(), jpeg.begin() + static_cast<long>(pos), jpeg.end());
    return out;
}

}  // namespace

int main(int argc, char** argv) {
    using namespace icewatch;
    if (argc != 2) {
        std::cerr << "usage: make_demo_recording DIR   (DIR must not hold a recording yet)\n";
        return 64;
    }
    try {
        v4l2::RecordingWriter writer(argv[1], "synthetic: tools/demo/make_demo_recording", v4l2::PixelFormat::kMjpeg,
                                     demo::kFrameWidth, demo::kFrameHeight, demo::kFps);
        for (int i = 0; i < demo::kFrames; ++i) {
            const cv::Mat frame = joinSideBySide(demo::renderEye(i, false), demo::renderEye(i, true));
            std::vector<std::uint8_t> jpeg;
            cv::imencode(".jpg", frame, jpeg, {cv::IMWRITE_JPEG_QUALITY, demo::kJpegQuality});
            const std::vector<std::uint8_t> mjpeg = withoutHuffmanTables(jpeg);
            writer.add(mjpeg.data(), mjpeg.size(), std::int64_t{i} * 1000000 / demo::kFps);
        }
        writer.finish();
    } catch (const std::exception& e) {
        std::cerr << "make_demo_recording: " << e.what() << "\n";
        return 73;
    }
    return 0;
}
