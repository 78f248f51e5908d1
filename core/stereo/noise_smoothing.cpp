// Noise-adaptive smoothing of the input: Census codes, Canny edges and gradient magnitudes are all
// differences of neighbouring pixels, which sensor noise of a few grey levels turns into noise of
// their own; a light blur matched to the image's own noise level restores them, while a clean
// image is left alone (blurring it would only lose detail).
//
// The noise estimate is Immerkær's (1996): the 3x3 operator [1 -2 1; -2 4 -2; 1 -2 1] cancels
// locally linear image structure, and the mean absolute response times sqrt(pi/2)/6 is the
// standard deviation of white Gaussian noise. Texture still leaks in, so the mean is taken per
// 8x8 block and the 5th percentile of the blocks is the estimate: the flattest parts of the image
// show the noise alone. On pure Gaussian noise it reads about 3/4 of sigma (the low percentile);
// the smoothing rule below is calibrated on this scale.
//
// The grey image then gets a pass of its own. It feeds the Census code (and the Canny and Harris
// bits): each neighbour's bits compare it with the window's reference within a band of a grey
// level or two, so on a flat, textureless surface noise of that size alone decides the bits and
// the code matches nothing better at the true disparity than elsewhere. The colour terms hold up:
// the AD sum over R, G, B is robust over 16 levels. On Teddy with Gaussian noise of sigma 2 the
// matcher fed the clean image's Census code loses 1.8 of its 2.9 points of extra bad pixels, fed
// the clean colour it loses none. The blur above is too weak at that noise (sigma < 0.25) and
// any stronger Gaussian blurs Cones' fine texture away (Cones+Teddy average bad rises). A
// bilateral filter instead averages only over neighbours within a few noise sigmas: flat areas
// are smoothed, texture edges kept.
#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "core/stereo/stages.hpp"

namespace icewatch::stereo::detail {

namespace {

// The flattest share of blocks (percent) that decides whether the grey pass runs, and the level
// it must exceed. Cones is textured all over: its 5th percentile reads 1.25 grey levels although
// its flattest 1 % read 0.81, about what a clean camera and 8-bit quantisation give (Teddy: 0.71
// and 0.54). With Gaussian noise of sigma 2 the flattest 1 % read 1.19 (Teddy) and 1.42 (Cones).
// On pure noise the 1st percentile reads about 0.65 sigma.
constexpr double kGreyPassPercentile = 1.0;
constexpr double kGreyPassNoiseFloor = 1.0;
// The filter's window; its range, in noise estimates, is Parameters::noiseGreyPassRange.
constexpr int kGreyPassDiameter = 5;
constexpr double kGreyPassSpatialSigma = 1.0;

}  // namespace

double estimateNoiseSigma(const cv::Mat& grey, double percentile) {
    CV_Assert(grey.type() == CV_8UC1);
    constexpr int kBlock = 8;
    if (grey.rows < kBlock + 2 || grey.cols < kBlock + 2) return 0.0;
    const cv::Mat kernel = (cv::Mat_<float>(3, 3) << 1, -2, 1, -2, 4, -2, 1, -2, 1);
    cv::Mat response;
    cv::filter2D(grey, response, CV_32F, kernel, {-1, -1}, 0, cv::BORDER_REFLECT);
    // Blocks inside the one-pixel frame whose response the border would distort.
    std::vector<double> blocks;
    const double scale = std::sqrt(CV_PI / 2.0) / (6.0 * kBlock * kBlock);
    for (int by = 1; by + kBlock < response.rows; by += kBlock)
        for (int bx = 1; bx + kBlock < response.cols; bx += kBlock) {
            double sum = 0.0;
            for (int y = by; y < by + kBlock; ++y) {
                const float* row = response.ptr<float>(y);
                for (int x = bx; x < bx + kBlock; ++x) sum += std::abs(row[x]);
            }
            blocks.push_back(scale * sum);
        }
    CV_Assert(percentile >= 0.0 && percentile < 100.0);
    const auto at = blocks.begin() + static_cast<std::ptrdiff_t>(static_cast<double>(blocks.size()) * percentile / 100.0);
    std::nth_element(blocks.begin(), at, blocks.end());
    return *at;
}

double smoothNoise(cv::Mat& bgr, cv::Mat& grey, double gain, double greyPassRange, double* noiseLeft) {
    if (gain <= 0.0) {
        if (noiseLeft) *noiseLeft = estimateNoiseSigma(grey);
        return 0.0;
    }
    // One grey level of "noise" is what quantisation and a clean camera give; 0.8 is the most
    // blur measured to pay (more smears disparity edges than it removes noise).
    double noise = estimateNoiseSigma(grey);
    double sigma = std::clamp(gain * (noise - 1.0), 0.0, 0.8);
    if (sigma > 0.2) {  // below this the kernel barely differs from identity
        cv::GaussianBlur(bgr, bgr, {0, 0}, sigma);
        cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
        noise = estimateNoiseSigma(grey);
    } else {
        sigma = 0.0;
    }
    // The grey pass, on what the blur left. After a strong blur the remaining noise is too smooth
    // for Immerkær's operator to see, and the pass stays off. The 1st percentile never reads above
    // the 5th, so an image whose 5th reads one grey level or less needs no second estimate.
    if (greyPassRange > 0.0 && noise > kGreyPassNoiseFloor &&
        estimateNoiseSigma(grey, kGreyPassPercentile) > kGreyPassNoiseFloor) {
        cv::Mat filtered;
        cv::bilateralFilter(grey, filtered, kGreyPassDiameter, greyPassRange * noise, kGreyPassSpatialSigma);
        grey = filtered;
        if (noiseLeft) noise = estimateNoiseSigma(grey);
    }
    if (noiseLeft) *noiseLeft = noise;
    return sigma;
}

int noiseAdaptiveCensusAlpha(int alpha, double gain, double noiseLeft, double noiseRight) {
    if (gain <= 0.0) return alpha;
    // One band for both eyes (codes made with different bands do not compare), from their mean
    // noise; capped where the band would swallow all but the strongest texture.
    const double band = std::min(gain * 0.5 * (noiseLeft + noiseRight), 32.0);
    return std::max(alpha, static_cast<int>(std::lround(band)));
}

}  // namespace icewatch::stereo::detail
