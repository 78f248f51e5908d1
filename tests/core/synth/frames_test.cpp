// Captures of several frames: one rendering of the geometry, then noise and JPEG per frame.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/common/error.hpp"
#include "core/synth/scene.hpp"

namespace icewatch::synth {
namespace {

SceneSpec smallBlade(int frames, double noiseSigma) {
    SceneSpec spec;
    spec.iceVolumeMm3 = 97609;
    spec.frameSize = {640, 240};
    spec.supersampling = 1;
    spec.frames = frames;
    spec.noiseSigma = noiseSigma;
    spec.jpegQuality = 100;
    return spec;
}

cv::Mat greyFloat(const std::vector<uchar>& jpeg) {
    const cv::Mat bgr = cv::imdecode(jpeg, cv::IMREAD_COLOR);
    cv::Mat grey, out;
    cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
    grey.convertTo(out, CV_32F);
    return out;
}

double rms(const cv::Mat& a, const cv::Mat& b) { return cv::norm(a, b, cv::NORM_L2) / std::sqrt(double(a.total())); }

TEST(SynthFrames, EachFrameHasItsOwnNoiseAndTheirMeanConvergesToTheNoiselessRender) {
    constexpr int kFrames = 8;
    const SyntheticScene noisy = renderScene(smallBlade(kFrames, 4.0));
    const SyntheticScene clean = renderScene(smallBlade(1, 0.0));
    ASSERT_EQ(noisy.beforeJpeg.size(), std::size_t{kFrames});
    ASSERT_EQ(noisy.afterJpeg.size(), std::size_t{kFrames});
    for (const auto* capture : {&noisy.beforeJpeg, &noisy.afterJpeg}) {
        const cv::Mat reference = greyFloat(capture == &noisy.beforeJpeg ? clean.beforeJpeg[0] : clean.afterJpeg[0]);
        cv::Mat sum = cv::Mat::zeros(reference.size(), CV_32F);
        for (std::size_t k = 0; k < capture->size(); ++k) {
            const cv::Mat frame = greyFloat((*capture)[k]);
            ASSERT_EQ(frame.size(), cv::Size(640, 240));
            if (k > 0) {
                EXPECT_GT(rms(frame, greyFloat((*capture)[k - 1])), 4.0) << "frame " << k + 1 << " repeats the noise";
            }
            sum += frame;
        }
        const double single = rms(greyFloat(capture->front()), reference);
        const double mean = rms(sum / kFrames, reference);
        EXPECT_NEAR(single, 4.0, 0.6);
        // σ/√8 plus what quantisation and JPEG leave: well under half of one frame's error.
        EXPECT_LT(mean, single / std::sqrt(double(kFrames)) * 1.25);
    }
}

TEST(SynthFrames, TheFirstFrameIsTheDecodedCapture) {
    const SyntheticScene scene = renderScene(smallBlade(3, 1.5));
    EXPECT_EQ(cv::norm(cv::imdecode(scene.beforeJpeg[0], cv::IMREAD_COLOR), scene.before, cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(cv::imdecode(scene.afterJpeg[0], cv::IMREAD_COLOR), scene.after, cv::NORM_INF), 0.0);
    // A burst starts with the frame a single capture would have given.
    const SyntheticScene single = renderScene(smallBlade(1, 1.5));
    EXPECT_EQ(single.beforeJpeg, std::vector<std::vector<uchar>>{scene.beforeJpeg[0]});
}

TEST(SynthFrames, FrameCountIsChecked) {
    EXPECT_THROW(renderScene(smallBlade(0, 1.5)), InvalidInput);
    EXPECT_THROW(renderScene(smallBlade(kMaxFrames + 1, 1.5)), InvalidInput);
}

}  // namespace
}  // namespace icewatch::synth
