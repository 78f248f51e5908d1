// Captures of several frames: one rendering of the geometry, then noise and JPEG per frame.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/common/error.hpp"
#include "core/synth/scene.hpp"
#include "core/synth/sensor.hpp"

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

// Another noise draw of the same scene: other noise in every frame, the same scene under it (the
// same truth, and the same picture but for the noise).
TEST(SynthFrames, AnotherNoiseDrawChangesTheNoiseAndNothingElse) {
    SceneSpec spec = smallBlade(2, 4.0);
    const SyntheticScene own = renderScene(spec);
    spec.noiseDraw = 7;
    const SyntheticScene other = renderScene(spec);
    EXPECT_EQ(own.iceVolumeMm3, other.iceVolumeMm3);
    const SyntheticScene clean = renderScene(smallBlade(1, 0.0));
    for (std::size_t k = 0; k < 2; ++k) {
        const cv::Mat a = greyFloat(own.afterJpeg[k]), b = greyFloat(other.afterJpeg[k]);
        // Two independent draws of sigma 4 differ by 4 sqrt 2; the same draw would not differ at all.
        EXPECT_NEAR(rms(a, b), 4.0 * std::sqrt(2.0), 0.8) << "frame " << k + 1;
        EXPECT_NEAR(rms(b, greyFloat(clean.afterJpeg[0])), 4.0, 0.6) << "frame " << k + 1;
    }
    spec.noiseDraw = 0;
    const SyntheticScene again = renderScene(spec);
    EXPECT_EQ(rms(greyFloat(again.beforeJpeg[0]), greyFloat(own.beforeJpeg[0])), 0.0) << "draw 0 is the seed's own";
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

// The lens blurs each eye on its own: a step inside the left eye is spread, the seam between the
// eyes is not (the right eye's light never reaches the left's last column), and the light is kept.
TEST(SynthFrames, TheLensBlursEachEyeAloneAndKeepsItsLight) {
    cv::Mat light(40, 200, CV_32F, cv::Scalar(0.2));
    light.colRange(50, 100).setTo(0.6);   // a step inside the left eye
    light.colRange(100, 200).setTo(0.8);  // the right eye, brighter
    const auto decode = [](const std::vector<uchar>& jpeg) { return greyFloat(jpeg); };
    const cv::Mat sharp = decode(exposeFrames(light, {1.0, 0.0, 100, 0.0, Tone::Linear}, {1}).front());
    const cv::Mat blurred = decode(exposeFrames(light, {1.0, 0.0, 100, 1.5, Tone::Linear}, {1}).front());
    EXPECT_NEAR(blurred.at<float>(20, 99), 0.6f * 255, 1.5) << "the left eye's last column, beside the seam";
    EXPECT_NEAR(blurred.at<float>(20, 100), 0.8f * 255, 1.5) << "the right eye's first column";
    EXPECT_NEAR(sharp.at<float>(20, 49), 0.2f * 255, 1.5);
    EXPECT_GT(blurred.at<float>(20, 49), 0.2f * 255 + 10) << "the step inside the eye is spread";
    EXPECT_LT(blurred.at<float>(20, 50), 0.6f * 255 - 10);
    EXPECT_NEAR(cv::mean(blurred.colRange(0, 100))[0], cv::mean(sharp.colRange(0, 100))[0], 0.5);
}

// A filmic curve keeps the order of light and puts the overcast sky about where the linear curve
// does, but it compresses the bright tones and, unlike a power law, a change of light does not
// scale every grey level by one factor: a dark surface changes more than a bright one.
TEST(SynthFrames, AFilmicCurveChangesDarkAndBrightSurfacesUnequally) {
    for (float l = 0.0f; l < 1.5f; l += 0.05f) EXPECT_LT(filmicTone(l), filmicTone(l + 0.05f)) << l;
    EXPECT_NEAR(filmicTone(0.8f), 0.82f, 0.02f);
    const float dark = filmicTone(0.85f * 0.4f) / filmicTone(0.4f), bright = filmicTone(0.85f * 0.8f) / filmicTone(0.8f);
    EXPECT_LT(dark, bright - 0.005f);
    const float slope = (filmicTone(0.62f) - filmicTone(0.58f)) / 0.04f;
    EXPECT_LT(slope, 0.6f) << "the blade's tones are compressed, its texture fainter";
    // Through the camera: the same light, the same filmic grey, whatever the gain's split.
    const cv::Mat light(8, 16, CV_32F, cv::Scalar(0.6));
    const cv::Mat grey = greyFloat(exposeFrames(light, {1.0, 0.0, 100, 0.0, Tone::Filmic}, {1}).front());
    EXPECT_NEAR(grey.at<float>(4, 4), 255 * filmicTone(0.6f), 1.0);
    // A power law scales every grey level alike under a change of light, by less than the light.
    const float g = gammaTone(0.85f * 0.4f) / gammaTone(0.4f);
    EXPECT_NEAR(gammaTone(0.85f * 0.8f) / gammaTone(0.8f), g, 1e-5f);
    EXPECT_NEAR(g, std::pow(0.85f, 1.0f / 2.2f), 1e-5f);
    EXPECT_NEAR(gammaTone(0.8f), 0.8f, 1e-6f);
}

}  // namespace
}  // namespace icewatch::synth
