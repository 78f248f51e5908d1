// The MJPEG path of every camera frame: the byte checks, the Huffman table insertion and libjpeg
// under our error manager. Any input is decoded or dropped with a reason.
#include <opencv2/core.hpp>

#include "drivers/v4l2/frame_decoder.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace icewatch::v4l2;
    static FrameDecoder decoder;
    static cv::Mat bgr;
    // The seeds are 64x32 frames; other sizes exercise the size check.
    checkFrameBytes(PixelFormat::kMjpeg, data, size, 64, 32);
    (void)decoder.decode(PixelFormat::kMjpeg, data, size, 64, 32, bgr);
    (void)decoder.decode(PixelFormat::kYuyv, data, size, 64, 32, bgr);
    return 0;
}
