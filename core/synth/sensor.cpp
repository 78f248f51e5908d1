// The sensor stage of the synthetic scenes: the geometry and shading of a capture are rendered
// once, and every frame of the capture gets its own sensor noise and its own JPEG encoding, as a
// burst from a fixed camera looking at a parked blade would.
#include "core/synth/sensor.hpp"

#include <algorithm>
#include <cmath>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace icewatch::synth {

float filmicTone(float light) {
    // Hable's filmic curve (a toe and a shoulder), white at 11.2, then sRGB's gamma.
    constexpr float a = 0.15f, b = 0.50f, c = 0.10f, d = 0.20f, e = 0.02f, f = 0.30f, white = 11.2f;
    constexpr float exposure = 4.0f;  // the sky's 0.8 to about 0.82
    auto hable = [=](float x) { return (x * (a * x + c * b) + d * e) / (x * (a * x + b) + d * f) - e / f; };
    const float x = std::max(0.0f, light) * exposure;
    return std::pow(hable(x) / hable(white), 1.0f / 2.2f);
}

float gammaTone(float light) {
    constexpr float sky = 0.8f;
    return sky * std::pow(std::max(0.0f, light) / sky, 1.0f / 2.2f);
}

namespace {

// Each eye through its own lens: the blur never reaches across the side-by-side seam.
cv::Mat blurredEyes(const cv::Mat& light, double sigmaPx) {
    if (sigmaPx <= 0) return light;
    cv::Mat out(light.size(), light.type());
    const int half = light.cols / 2;
    for (const cv::Rect eye : {cv::Rect(0, 0, half, light.rows), cv::Rect(half, 0, light.cols - half, light.rows)}) {
        cv::Mat blurred;
        cv::GaussianBlur(light(eye), blurred, {0, 0}, sigmaPx, sigmaPx, cv::BORDER_REPLICATE | cv::BORDER_ISOLATED);
        blurred.copyTo(out(eye));
    }
    return out;
}

std::vector<uchar> exposeFrame(const cv::Mat& light, const Exposure& exposure, std::uint32_t noiseSeed) {
    cv::Mat grey = light * exposure.gain;
    if (exposure.tone != Tone::Linear) {
        const auto curve = exposure.tone == Tone::Filmic ? filmicTone : gammaTone;
        for (int y = 0; y < grey.rows; ++y) {
            float* row = grey.ptr<float>(y);
            for (int x = 0; x < grey.cols; ++x) row[x] = curve(row[x]);
        }
    }
    grey *= 255.0;
    if (exposure.noiseSigma > 0) {
        cv::Mat noise(grey.size(), CV_32F);
        cv::RNG random(noiseSeed);
        random.fill(noise, cv::RNG::NORMAL, 0.0, exposure.noiseSigma);
        grey += noise;
    }
    cv::Mat grey8;
    grey.convertTo(grey8, CV_8U);  // rounds and saturates, as the sensor's 8 bits do
    cv::Mat bgr;
    cv::cvtColor(grey8, bgr, cv::COLOR_GRAY2BGR);
    std::vector<uchar> jpeg;
    cv::imencode(".jpg", bgr, jpeg, {cv::IMWRITE_JPEG_QUALITY, exposure.jpegQuality});
    return jpeg;
}

}  // namespace

std::vector<std::vector<uchar>> exposeFrames(const cv::Mat& light, const Exposure& exposure,
                                             const std::vector<std::uint32_t>& noiseSeeds) {
    std::vector<std::vector<uchar>> frames(noiseSeeds.size());
    const cv::Mat seen = blurredEyes(light, exposure.blurPx);  // once: the lens is the same for every frame
    // One frame per task: each is a pure function of its seed, so the thread count changes nothing.
    cv::parallel_for_(cv::Range(0, static_cast<int>(noiseSeeds.size())), [&](const cv::Range& range) {
        for (int k = range.start; k < range.end; ++k) {
            frames[static_cast<std::size_t>(k)] = exposeFrame(seen, exposure, noiseSeeds[static_cast<std::size_t>(k)]);
        }
    });
    return frames;
}

}  // namespace icewatch::synth
