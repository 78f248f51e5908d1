// The matcher's change against the texture tracks' (matcher_push.hpp).
#include "core/volume/matcher_push.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

namespace icewatch::volume {

namespace {

std::optional<double> bilinear(const cv::Mat& disparity, cv::Point2d at) {
    const int x = static_cast<int>(std::floor(at.x)), y = static_cast<int>(std::floor(at.y));
    if (x < 0 || y < 0 || x + 1 >= disparity.cols || y + 1 >= disparity.rows) return std::nullopt;
    const float a = disparity.at<float>(y, x), b = disparity.at<float>(y, x + 1);
    const float c = disparity.at<float>(y + 1, x), d = disparity.at<float>(y + 1, x + 1);
    if (!(a > 0 && b > 0 && c > 0 && d > 0)) return std::nullopt;
    const double fx = at.x - x, fy = at.y - y;
    return (1 - fy) * ((1 - fx) * a + fx * b) + fy * ((1 - fx) * c + fx * d);
}

}  // namespace

MatcherPush matcherPush(const std::vector<TextureTrack>& tracks, const std::vector<std::uint8_t>& use,
                        const cv::Mat& baselineDisparity, const cv::Mat& currentDisparity,
                        const cv::Mat& possibleIce, double correlationFactor) {
    CV_Assert(use.size() == tracks.size() && baselineDisparity.type() == CV_32FC1 &&
              currentDisparity.type() == CV_32FC1 && possibleIce.type() == CV_8UC1);
    double sum = 0, sumSquares = 0;
    int n = 0;
    for (std::size_t i = 0; i < tracks.size(); ++i) {
        const TextureTrack& t = tracks[i];
        if (!use[i] || !t.onObject || !possibleIce.at<std::uint8_t>(t.pixel)) continue;
        const float before = baselineDisparity.at<float>(t.pixel);
        const std::optional<double> after = bilinear(currentDisparity, t.currentPixel);
        if (!(before > 0) || !after) continue;
        const double push = (*after - t.currentDisparity) - (before - t.baselineDisparity);
        sum += push;
        sumSquares += push * push;
        ++n;
    }
    MatcherPush out;
    out.samples = n;
    if (n < 2) return out;
    out.meanPx = sum / n;
    const double variance = std::max(0.0, (sumSquares - n * out.meanPx * out.meanPx) / (n - 1));
    out.sigmaPx = std::sqrt(variance * std::max(1.0, correlationFactor) / n);
    return out;
}

}  // namespace icewatch::volume
