// Texture along the image rows where the ice was read (row_texture.hpp).
#include "core/volume/row_texture.hpp"

#include <cmath>
#include <cstdint>

#include <opencv2/imgproc.hpp>

namespace icewatch::volume {

double imageNoiseGrey(const cv::Mat& grey, const cv::Mat& mask) {
    CV_Assert(grey.type() == CV_32FC1 && mask.type() == CV_8UC1 && mask.size() == grey.size());
    const cv::Matx33f laplacian(1, -2, 1, -2, 4, -2, 1, -2, 1);
    cv::Mat response;
    cv::filter2D(grey, response, CV_32F, laplacian, {-1, -1}, 0, cv::BORDER_REPLICATE);
    double sum = 0;
    long count = 0;
    for (int y = 1; y + 1 < grey.rows; ++y) {
        const float* r = response.ptr<float>(y);
        const std::uint8_t* m = mask.ptr<std::uint8_t>(y);
        for (int x = 1; x + 1 < grey.cols; ++x) {
            if (!m[x]) continue;
            sum += std::abs(r[x]);
            ++count;
        }
    }
    if (count == 0) return 0.0;
    // E|N(0, 36σ²)| = 6σ·sqrt(2/π).
    return std::sqrt(M_PI / 2.0) / 6.0 * sum / double(count);
}

cv::Mat rowTextureGreyPerPx(const cv::Mat& grey, double noiseGrey, int radiusPx) {
    CV_Assert(grey.type() == CV_32FC1 && radiusPx >= 1);
    const cv::Matx13f centralDifference(-0.5f, 0.0f, 0.5f);
    cv::Mat along;
    cv::filter2D(grey, along, CV_32F, centralDifference, {-1, -1}, 0, cv::BORDER_REPLICATE);
    cv::Mat power;
    cv::multiply(along, along, power);
    const int side = 2 * radiusPx + 1;
    cv::boxFilter(power, power, CV_32F, {side, side}, {-1, -1}, true, cv::BORDER_REPLICATE);
    // The central difference of white noise σ has variance σ²/2.
    const auto noisePower = static_cast<float>(noiseGrey * noiseGrey / 2.0);
    cv::Mat texture(grey.size(), CV_32F);
    power.forEach<float>([&](const float& p, const int* at) {
        texture.at<float>(at[0], at[1]) = std::sqrt(std::max(0.0f, p - noisePower));
    });
    return texture;
}

FaintIce faintIce(const cv::Mat& grey, const cv::Mat& thicknessMm, const RowTextureOptions& o) {
    CV_Assert(thicknessMm.type() == CV_32FC1 && thicknessMm.size() == grey.size());
    const cv::Mat read = thicknessMm == thicknessMm;  // not NaN
    const cv::Mat texture = rowTextureGreyPerPx(grey, imageNoiseGrey(grey, read), o.radiusPx);
    FaintIce out;
    for (int y = 0; y < grey.rows; ++y) {
        const float* t = thicknessMm.ptr<float>(y);
        const float* g = texture.ptr<float>(y);
        for (int x = 0; x < grey.cols; ++x) {
            if (!(t[x] >= o.minIceMm)) continue;
            ++out.icePixels;
            if (g[x] < o.minGreyPerPx) ++out.faintPixels;
        }
    }
    return out;
}

}  // namespace icewatch::volume
