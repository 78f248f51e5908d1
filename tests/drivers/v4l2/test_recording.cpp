#include "tests/drivers/v4l2/test_recording.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "tools/demo/demo_scene.hpp"

namespace icewatch::test {

v4l2::Recording makeMjpegRecording(const std::filesystem::path& dir, int frames, int eyeWidth, int height) {
    v4l2::RecordingWriter writer(dir, "test", v4l2::PixelFormat::kMjpeg, 2 * eyeWidth, height, 30);
    for (int i = 0; i < frames; ++i) {
        const cv::Mat frame =
            joinSideBySide(demo::renderEye(i, false, eyeWidth, height), demo::renderEye(i, true, eyeWidth, height));
        std::vector<std::uint8_t> jpeg;
        cv::imencode(".jpg", frame, jpeg, {cv::IMWRITE_JPEG_QUALITY, 90});
        writer.add(jpeg.data(), jpeg.size(), 1000 + std::int64_t{i} * 33333);
    }
    writer.finish();
    return v4l2::readRecording(dir);
}

v4l2::Recording makeYuyvRecording(const std::filesystem::path& dir, int frames, int eyeWidth, int height) {
    const int width = 2 * eyeWidth;
    v4l2::RecordingWriter writer(dir, "test", v4l2::PixelFormat::kYuyv, width, height, 5);
    for (int i = 0; i < frames; ++i) {
        std::vector<std::uint8_t> yuyv(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 2);
        for (std::size_t p = 0; p < yuyv.size(); ++p) {
            yuyv[p] = static_cast<std::uint8_t>(demo::hash(static_cast<std::int32_t>(p), i, 99) & 255);
        }
        writer.add(yuyv.data(), yuyv.size(), std::int64_t{i} * 200000);
    }
    writer.finish();
    return v4l2::readRecording(dir);
}

std::vector<StereoPair> decodeRecording(const v4l2::Recording& recording) {
    std::vector<StereoPair> pairs;
    for (std::size_t i = 0; i < recording.frames.size(); ++i) {
        std::vector<std::uint8_t> bytes = recording.readFrame(i);
        cv::Mat bgr;
        if (recording.format == v4l2::PixelFormat::kMjpeg) {
            bgr = cv::imdecode(bytes, cv::IMREAD_COLOR);
        } else {
            cv::cvtColor(cv::Mat(recording.height, recording.width, CV_8UC2, bytes.data()), bgr,
                         cv::COLOR_YUV2BGR_YUYV);
        }
        pairs.push_back(splitSideBySide(bgr));
    }
    return pairs;
}

int matchingSource(const StereoPair& pair, const std::vector<StereoPair>& sources) {
    for (std::size_t i = 0; i < sources.size(); ++i) {
        const StereoPair& s = sources[i];
        if (pair.left.size() == s.left.size() && pair.left.type() == s.left.type() &&
            pair.right.size() == s.right.size() && cv::norm(pair.left, s.left, cv::NORM_INF) == 0 &&
            cv::norm(pair.right, s.right, cv::NORM_INF) == 0) {
            return static_cast<int>(i);
        }
    }
    return -1;
}

}  // namespace icewatch::test
