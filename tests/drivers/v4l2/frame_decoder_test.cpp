// The decoder: same pixels as an independent decode, Huffman-less MJPEG handled, every kind of
// damage dropped rather than decoded into something plausible.
#include "drivers/v4l2/frame_decoder.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "tools/demo/demo_scene.hpp"

namespace icewatch::v4l2 {
namespace {

std::vector<std::uint8_t> testJpeg(int width = 320, int height = 240) {
    const cv::Mat image = demo::renderEye(0, false, width, height);
    std::vector<std::uint8_t> jpeg;
    cv::imencode(".jpg", image, jpeg, {cv::IMWRITE_JPEG_QUALITY, 90});
    return jpeg;
}

TEST(FrameDecoder, DecodesMjpegToTheSamePixelsAsOpenCv) {
    const auto jpeg = testJpeg();
    FrameDecoder decoder;
    cv::Mat bgr;
    ASSERT_FALSE(decoder.decode(PixelFormat::kMjpeg, jpeg.data(), jpeg.size(), 320, 240, bgr));
    const cv::Mat reference = cv::imdecode(jpeg, cv::IMREAD_COLOR);
    EXPECT_EQ(cv::norm(bgr, reference, cv::NORM_INF), 0);
}

TEST(FrameDecoder, InsertsTheStandardHuffmanTablesWhenTheFrameHasNone) {
    const auto jpeg = testJpeg();
    const auto mjpeg = withoutHuffmanTables(jpeg.data(), jpeg.size());
    ASSERT_TRUE(hasHuffmanTables(jpeg.data(), jpeg.size()));
    ASSERT_FALSE(hasHuffmanTables(mjpeg.data(), mjpeg.size()));
    const auto patched = withStandardHuffmanTables(mjpeg.data(), mjpeg.size());
    EXPECT_TRUE(hasHuffmanTables(patched.data(), patched.size()));
    FrameDecoder decoder;
    cv::Mat fromMjpeg;
    cv::Mat fromJpeg;
    ASSERT_FALSE(decoder.decode(PixelFormat::kMjpeg, mjpeg.data(), mjpeg.size(), 320, 240, fromMjpeg));
    ASSERT_FALSE(decoder.decode(PixelFormat::kMjpeg, jpeg.data(), jpeg.size(), 320, 240, fromJpeg));
    EXPECT_EQ(cv::norm(fromMjpeg, fromJpeg, cv::NORM_INF), 0);
}

TEST(FrameDecoder, DropsAJpegThatDecodesOnlyWithWarnings) {
    auto jpeg = testJpeg();
    // Damage the entropy-coded data in the middle, keeping SOI and EOI: libjpeg would go on and
    // paint a plausible picture with a warning.
    for (std::size_t i = jpeg.size() / 2; i < jpeg.size() / 2 + 40; ++i) jpeg[i] = 0xFF;
    FrameDecoder decoder;
    cv::Mat bgr;
    EXPECT_EQ(decoder.decode(PixelFormat::kMjpeg, jpeg.data(), jpeg.size(), 320, 240, bgr), DropReason::kCorruptJpeg);
    EXPECT_FALSE(decoder.message().empty());
    // The decoder is usable again after a failure.
    const auto good = testJpeg();
    EXPECT_FALSE(decoder.decode(PixelFormat::kMjpeg, good.data(), good.size(), 320, 240, bgr));
}

TEST(FrameDecoder, DropsTruncatedFramesAndGarbage) {
    const auto jpeg = testJpeg();
    FrameDecoder decoder;
    cv::Mat bgr;
    EXPECT_EQ(decoder.decode(PixelFormat::kMjpeg, jpeg.data(), jpeg.size() / 2, 320, 240, bgr),
              DropReason::kNoJpegMarkers);
    EXPECT_EQ(decoder.decode(PixelFormat::kMjpeg, jpeg.data(), 64, 320, 240, bgr), DropReason::kShortFrame);
    std::vector<std::uint8_t> noise(4096, 0x5A);
    EXPECT_EQ(decoder.decode(PixelFormat::kMjpeg, noise.data(), noise.size(), 320, 240, bgr),
              DropReason::kNoJpegMarkers);
    // SOI and EOI around garbage: libjpeg's error path.
    noise[0] = 0xFF, noise[1] = 0xD8, noise[4094] = 0xFF, noise[4095] = 0xD9;
    EXPECT_EQ(decoder.decode(PixelFormat::kMjpeg, noise.data(), noise.size(), 320, 240, bgr),
              DropReason::kCorruptJpeg);
}

TEST(FrameDecoder, AcceptsZeroPaddingAfterEoiButChecksTheSize) {
    auto jpeg = testJpeg();
    jpeg.resize(jpeg.size() + 100, 0x00);
    FrameDecoder decoder;
    cv::Mat bgr;
    EXPECT_FALSE(decoder.decode(PixelFormat::kMjpeg, jpeg.data(), jpeg.size(), 320, 240, bgr));
    EXPECT_EQ(decoder.decode(PixelFormat::kMjpeg, jpeg.data(), jpeg.size(), 640, 240, bgr), DropReason::kSizeMismatch);
}

TEST(FrameDecoder, ConvertsYuyvAndRejectsShortYuyv) {
    std::vector<std::uint8_t> yuyv(64 * 8 * 2);
    for (std::size_t i = 0; i < yuyv.size(); ++i) yuyv[i] = static_cast<std::uint8_t>(i * 37);
    FrameDecoder decoder;
    cv::Mat bgr;
    ASSERT_FALSE(decoder.decode(PixelFormat::kYuyv, yuyv.data(), yuyv.size(), 64, 8, bgr));
    cv::Mat reference;
    cv::cvtColor(cv::Mat(8, 64, CV_8UC2, yuyv.data()), reference, cv::COLOR_YUV2BGR_YUYV);
    EXPECT_EQ(cv::norm(bgr, reference, cv::NORM_INF), 0);
    EXPECT_EQ(decoder.decode(PixelFormat::kYuyv, yuyv.data(), yuyv.size() - 2, 64, 8, bgr), DropReason::kShortFrame);
}

}  // namespace
}  // namespace icewatch::v4l2
