// The sensor stage of the synthetic scenes: the geometry and shading of a capture are rendered
// once, and every frame of the capture gets its own sensor noise and its own JPEG encoding, as a
// burst from a fixed camera looking at a parked blade would.
#include "core/synth/sensor.hpp"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace icewatch::synth {

namespace {

std::vector<uchar> exposeFrame(const cv::Mat& light, const Exposure& exposure, std::uint32_t noiseSeed) {
    cv::Mat grey = light * (255.0 * exposure.gain);
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
    // One frame per task: each is a pure function of its seed, so the thread count changes nothing.
    cv::parallel_for_(cv::Range(0, static_cast<int>(noiseSeeds.size())), [&](const cv::Range& range) {
        for (int k = range.start; k < range.end; ++k) {
            frames[static_cast<std::size_t>(k)] = exposeFrame(light, exposure, noiseSeeds[static_cast<std::size_t>(k)]);
        }
    });
    return frames;
}

}  // namespace icewatch::synth
