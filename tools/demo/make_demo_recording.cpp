// make_demo_recording DIR: writes the bundled demo recording (tools/demo/recording) from the
// synthetic scene in demo_scene.hpp. Frames are MJPEG without Huffman tables, as UVC cameras send
// them, so the demo exercises the decoder's table insertion too.
#include <filesystem>
#include <iostream>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "core/common/side_by_side.hpp"
#include "drivers/v4l2/frame_decoder.hpp"
#include "drivers/v4l2/recording.hpp"
#include "tools/demo/demo_scene.hpp"

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
            const std::vector<std::uint8_t> mjpeg = v4l2::withoutHuffmanTables(jpeg.data(), jpeg.size());
            writer.add(mjpeg.data(), mjpeg.size(), std::int64_t{i} * 1000000 / demo::kFps);
        }
        writer.finish();
    } catch (const std::exception& e) {
        std::cerr << "make_demo_recording: " << e.what() << "\n";
        return 73;
    }
    return 0;
}
