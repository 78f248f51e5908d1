// Texture along the image rows where ice was read or where the object's texture went (row_texture.hpp).
#include "core/volume/row_texture.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "core/volume/robust_statistics.hpp"

namespace icewatch::volume {

double imageNoiseGrey(const cv::Mat& grey, const cv::Mat& mask) {
    CV_Assert(grey.type() == CV_32FC1 && mask.type() == CV_8UC1 && mask.size() == grey.size());
    const cv::Matx33f laplacian(1, -2, 1, -2, 4, -2, 1, -2, 1);
    cv::Mat response;
    cv::filter2D(grey, response, CV_32F, laplacian, {-1, -1}, 0, cv::BORDER_REPLICATE);
    std::vector<float> magnitudes;
    for (int y = 1; y + 1 < grey.rows; ++y) {
        const float* r = response.ptr<float>(y);
        const std::uint8_t* m = mask.ptr<std::uint8_t>(y);
        for (int x = 1; x + 1 < grey.cols; ++x)
            if (m[x]) magnitudes.push_back(std::abs(r[x]));
    }
    if (magnitudes.empty()) return 0.0;
    // The median of |N(0, 36σ²)| is 6σ / kMadToSigma.
    return kMadToSigma * double(median(std::move(magnitudes))) / 6.0;
}

namespace {

// The local mean over the (2r+1)² window of the squared horizontal central difference.
cv::Mat rowDifferencePower(const cv::Mat& image, int radiusPx) {
    const cv::Matx13f centralDifference(-0.5f, 0.0f, 0.5f);
    cv::Mat along;
    cv::filter2D(image, along, CV_32F, centralDifference, {-1, -1}, 0, cv::BORDER_REPLICATE);
    cv::Mat power;
    cv::multiply(along, along, power);
    const int side = 2 * radiusPx + 1;
    cv::boxFilter(power, power, CV_32F, {side, side}, {-1, -1}, true, cv::BORDER_REPLICATE);
    return power;
}

}  // namespace

cv::Mat rowNoisePower(const cv::Mat& noise, int radiusPx) {
    CV_Assert(noise.type() == CV_32FC1 && radiusPx >= 1);
    return rowDifferencePower(noise, radiusPx);
}

cv::Mat rowTextureGreyPerPx(const cv::Mat& grey, const cv::Mat& noisePower, int radiusPx) {
    CV_Assert(grey.type() == CV_32FC1 && radiusPx >= 1);
    CV_Assert(noisePower.type() == CV_32FC1 && noisePower.size() == grey.size());
    const cv::Mat power = rowDifferencePower(grey, radiusPx);
    cv::Mat texture(grey.size(), CV_32F);
    power.forEach<float>([&](const float& p, const int* at) {
        texture.at<float>(at[0], at[1]) = std::sqrt(std::max(0.0f, p - noisePower.at<float>(at[0], at[1])));
    });
    return texture;
}

cv::Mat rowTextureGreyPerPx(const cv::Mat& grey, double noiseGrey, int radiusPx) {
    // The central difference of white noise σ has variance σ²/2.
    return rowTextureGreyPerPx(grey, cv::Mat(grey.size(), CV_32F, cv::Scalar(noiseGrey * noiseGrey / 2.0)), radiusPx);
}

namespace {

// A capture's texture along the rows, its noise's taken off: the power its noise draw shows where
// it has one, else white noise at the level the image's second differences give.
cv::Mat captureRowTexture(const cv::Mat& grey, const cv::Mat& noise, const cv::Mat& object, int radiusPx) {
    if (noise.empty()) return rowTextureGreyPerPx(grey, imageNoiseGrey(grey, object), radiusPx);
    CV_Assert(noise.size() == grey.size());
    return rowTextureGreyPerPx(grey, rowNoisePower(noise, radiusPx), radiusPx);
}

}  // namespace

FaintIce faintIce(const RowTextureInputs& in, const RowTextureOptions& o) {
    const cv::Size size = in.currentGrey.size();
    CV_Assert(in.baselineGrey.size() == size && in.baselineObject.size() == size && in.thicknessMm.size() == size);
    CV_Assert(in.thicknessMm.type() == CV_32FC1 && in.baselineObject.type() == CV_8UC1);
    CV_Assert(in.unreadLost.empty() || (in.unreadLost.size() == size && in.unreadLost.type() == CV_8UC1));
    // Without a noise draw the noise is the image's, wherever on the object it is read (the object moved little).
    const cv::Mat before = captureRowTexture(in.baselineGrey, in.baselineNoise, in.baselineObject, o.radiusPx);
    const cv::Mat now = captureRowTexture(in.currentGrey, in.currentNoise, in.baselineObject, o.radiusPx);
    cv::Mat lost = cv::Mat::zeros(size, CV_8U);
    for (int y = 0; y < size.height; ++y) {
        const std::uint8_t* object = in.baselineObject.ptr<std::uint8_t>(y);
        const float* had = before.ptr<float>(y);
        for (int x = 0; x < size.width; ++x) {
            if (!object[x]) continue;
            const cv::Point2d at = in.toCurrent({double(x), double(y)});
            // The range first (NaN fails it too): a huge place must not reach the rounding.
            if (!(at.x > -0.5 && at.y > -0.5 && at.x < size.width - 0.5 && at.y < size.height - 0.5)) continue;
            const int u = static_cast<int>(std::lround(at.x)), v = static_cast<int>(std::lround(at.y));
            const float has = now.at<float>(v, u);
            if (had[x] >= o.minGreyPerPx && has < o.minGreyPerPx && has < 0.5 * in.lightRatio * had[x]) lost.at<std::uint8_t>(v, u) = 255;
        }
    }
    if (!in.unreadLost.empty()) {
        // Where ice was read, something placed it (a block's plain top is carried from its edges);
        // where none was, the matcher carried the blade's surface over what hid its texture.
        cv::Mat readThick;
        cv::compare(in.thicknessMm, o.minIceMm, readThick, cv::CMP_GE);  // NaN compares false
        lost |= in.unreadLost & ~readThick;
    }
    FaintIce out;
    for (int y = 0; y < size.height; ++y) {
        const float* t = in.thicknessMm.ptr<float>(y);
        const float* g = now.ptr<float>(y);
        const std::uint8_t* gone = lost.ptr<std::uint8_t>(y);
        for (int x = 0; x < size.width; ++x) {
            if (gone[x]) {
                ++out.icePixels;
                ++out.faintPixels;
                ++out.lostPixels;
            } else if (t[x] >= o.minIceMm) {
                ++out.icePixels;
                if (g[x] < o.minGreyPerPx) ++out.faintPixels;
            }
        }
    }
    return out;
}

}  // namespace icewatch::volume
