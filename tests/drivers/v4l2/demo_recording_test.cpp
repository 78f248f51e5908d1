// The bundled demo recording (tools/demo/recording) holds what its generator says: the synthetic
// scene, right eye = left eye shifted by the known disparity, within JPEG tolerance.
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "drivers/v4l2/frame_decoder.hpp"
#include "drivers/v4l2/recording.hpp"
#include "tests/support/test_paths.hpp"
#include "tools/demo/demo_scene.hpp"

namespace icewatch::v4l2 {
namespace {

// Mean absolute difference of the luma: JPEG keeps luma at full resolution and subsamples
// chroma, so luma is where "the same picture" can be judged tightly.
double meanAbsDiff(const cv::Mat& a, const cv::Mat& b) {
    cv::Mat grayA;
    cv::Mat grayB;
    cv::cvtColor(a, grayA, cv::COLOR_BGR2GRAY);
    cv::cvtColor(b, grayB, cv::COLOR_BGR2GRAY);
    cv::Mat diff;
    cv::absdiff(grayA, grayB, diff);
    return cv::mean(diff)[0];
}

TEST(DemoRecording, IsSmallSideBySideMjpegWithoutHuffmanTables) {
    const Recording r = readRecording(test::sourceDir() / "tools/demo/recording");
    EXPECT_EQ(r.format, PixelFormat::kMjpeg);
    EXPECT_EQ(r.width, demo::kFrameWidth);
    EXPECT_EQ(r.height, demo::kFrameHeight);
    ASSERT_EQ(r.frames.size(), static_cast<std::size_t>(demo::kFrames));
    std::size_t total = 0;
    for (const RecordedFrame& f : r.frames) total += f.bytes;
    EXPECT_LT(total, 5u * 1024 * 1024);
    const auto first = r.readFrame(0);
    EXPECT_FALSE(hasHuffmanTables(first.data(), first.size()));  // as UVC cameras send MJPEG
}

TEST(DemoRecording, HoldsTheSceneWithItsKnownDisparity) {
    const Recording r = readRecording(test::sourceDir() / "tools/demo/recording");
    FrameDecoder decoder;
    const int eyeWidth = r.width / 2;
    const int d = demo::kDisparityPx;
    for (std::size_t i = 0; i < r.frames.size(); i += 5) {
        const auto bytes = r.readFrame(i);
        cv::Mat bgr;
        ASSERT_FALSE(decoder.decode(r.format, bytes.data(), bytes.size(), r.width, r.height, bgr));
        const cv::Mat left = bgr(cv::Rect(0, 0, eyeWidth, r.height));
        const cv::Mat right = bgr(cv::Rect(eyeWidth, 0, eyeWidth, r.height));
        // Against the generator's scene: JPEG at quality 85 keeps luma within a grey level on average
        // (measured 0.60).
        const int frame = static_cast<int>(i);
        EXPECT_LT(meanAbsDiff(left, demo::renderEye(frame, false)), 1.5) << "frame " << i;
        EXPECT_LT(meanAbsDiff(right, demo::renderEye(frame, true)), 1.5) << "frame " << i;
        // The disparity is there, and it is this one, not a neighbour (measured: 0.00 at d, as the
        // shift is whole 8x8 luma blocks; 1.72 at d +- 1).
        const cv::Rect overlap(0, 0, eyeWidth - d - 2, r.height);
        const double atD = meanAbsDiff(right(overlap), left(overlap + cv::Point(d, 0)));
        const double atDPlus1 = meanAbsDiff(right(overlap), left(overlap + cv::Point(d + 1, 0)));
        const double atDMinus1 = meanAbsDiff(right(overlap), left(overlap + cv::Point(d - 1, 0)));
        EXPECT_LT(atD, 0.5);
        EXPECT_GT(atDPlus1, atD + 1.0);
        EXPECT_GT(atDMinus1, atD + 1.0);
    }
}

}  // namespace
}  // namespace icewatch::v4l2
