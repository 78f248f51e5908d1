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
#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "core/stereo/stages.hpp"

namespace icewatch::stereo::detail {

double estimateNoiseSigma(const cv::Mat& grey) {
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
    const auto at = blocks.begin() + static_cast<std::ptrdiff_t>(blocks.size() * 5 / 100);
    std::nth_element(blocks.begin(), at, blocks.end());
    return *at;
}

double smoothNoise(cv::Mat& bgr, cv::Mat& grey, double gain) {
    if (gain <= 0.0) return 0.0;
    // One grey level of "noise" is what quantisation and a clean camera give; 0.8 is the most
    // blur measured to pay (more smears disparity edges than it removes noise).
    const double sigma = std::clamp(gain * (estimateNoiseSigma(grey) - 1.0), 0.0, 0.8);
    if (sigma <= 0.2) return 0.0;  // below this the kernel barely differs from identity
    cv::GaussianBlur(bgr, bgr, {0, 0}, sigma);
    cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
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
