#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

namespace icewatch::synth {

// How light becomes grey levels (scene.hpp: ToneCurve says what each does to a change of light).
enum class Tone { Linear, Gamma, Filmic };

// How the camera turns the light of one capture into the frames it delivers.
struct Exposure {
    double gain = 1.0;        // the scene's illumination relative to the baseline capture's
    double noiseSigma = 1.5;  // Gaussian sensor noise, grey levels (0..255)
    int jpegQuality = 90;     // MJPEG compression as the camera applies it, 1..100
    double blurPx = 0.0;      // the lens's blur: a Gaussian of this sigma, px, on each eye (0: none)
    Tone tone = Tone::Linear;
};

// A power law of 1/2.2, the sky's 0.8 kept where the linear curve puts it.
float gammaTone(float light);

// A filmic tone curve of light (0..1 for the linear curve's range): a toe, a compressed shoulder,
// then sRGB's gamma, the light scaled so that the sky (0.8) stays about where the linear curve puts
// it. Light scaled by g is not grey scaled by one factor: a bright surface changes less than a dark one.
float filmicTone(float light);

// The frames of one capture, each exactly as the camera's MJPEG stream would deliver it: the
// noiseless side-by-side render (CV_32F, 0..1), each eye blurred by the lens, times the gain,
// through the tone curve, plus noise of its own (one seed per frame), rounded and saturated to 8
// bits, encoded as a BGR JPEG.
std::vector<std::vector<uchar>> exposeFrames(const cv::Mat& light, const Exposure& exposure,
                                             const std::vector<std::uint32_t>& noiseSeeds);

}  // namespace icewatch::synth
