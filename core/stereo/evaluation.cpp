// Scoring disparities against ground truth and the noise models of the seed paper's robustness
// tables. cv::RNG seeded explicitly keeps every noisy run reproducible.
#include "core/stereo/evaluation.hpp"

#include <cmath>
#include <stdexcept>

#include "core/common/error.hpp"
#include "core/stereo/matcher.hpp"

namespace icewatch::stereo {

DisparityScore scoreDisparity(const cv::Mat& disparity, const cv::Mat& gt, double gtScale, const cv::Mat& mask,
                              double threshold) {
    if (disparity.type() != CV_32FC1 || gt.type() != CV_8UC1 || (!mask.empty() && mask.type() != CV_8UC1)) {
        throw InvalidInput("scoring: disparity must be 32-bit float, ground truth and mask 8-bit grey");
    }
    if (gt.size() != disparity.size() || (!mask.empty() && mask.size() != disparity.size())) {
        throw InvalidInput("scoring: disparity, ground truth and mask sizes differ");
    }
    if (!(gtScale > 0.0)) throw InvalidInput("scoring: ground-truth scale must be positive");
    long long bad = 0, evaluated = 0, valid = 0;
    for (int y = 0; y < disparity.rows; ++y) {
        const auto* d = disparity.ptr<float>(y);
        const auto* g = gt.ptr<std::uint8_t>(y);
        const auto* m = mask.empty() ? nullptr : mask.ptr<std::uint8_t>(y);
        for (int x = 0; x < disparity.cols; ++x) {
            const bool has = d[x] >= 0.0f && std::isfinite(d[x]);
            valid += has;
            if ((m && m[x] != 255) || g[x] == 0) continue;
            ++evaluated;
            if (!has || std::abs(d[x] - g[x] / gtScale) > threshold) ++bad;
        }
    }
    DisparityScore score;
    score.evaluated = static_cast<int>(evaluated);
    score.badPercent = evaluated ? 100.0 * static_cast<double>(bad) / static_cast<double>(evaluated) : 0.0;
    score.validPercent = 100.0 * static_cast<double>(valid) / static_cast<double>(disparity.total());
    return score;
}

NoiseSpec parseNoise(const std::string& text) {
    NoiseSpec spec;
    spec.text = text;
    if (text == "none") return spec;
    const auto colon = text.find(':');
    const std::string kind = text.substr(0, colon);
    if (colon == std::string::npos || (kind != "saltpepper" && kind != "gauss")) {
        throw InvalidInput("noise \"" + text + "\": expected none, saltpepper:PERCENT or gauss:SIGMA");
    }
    double amount = 0.0;
    try {
        std::size_t used = 0;
        amount = std::stod(text.substr(colon + 1), &used);
        if (used != text.size() - colon - 1) throw std::invalid_argument("trailing characters");
    } catch (const std::exception&) {
        throw InvalidInput("noise \"" + text + "\": the amount is not a number");
    }
    if (kind == "saltpepper") {
        if (!(amount >= 0.0 && amount <= 100.0)) throw InvalidInput("noise \"" + text + "\": percent must be 0..100");
        spec.kind = NoiseSpec::Kind::SaltPepper;
    } else {
        if (!(amount >= 0.0 && amount <= 255.0)) throw InvalidInput("noise \"" + text + "\": sigma must be 0..255");
        spec.kind = NoiseSpec::Kind::Gaussian;
    }
    spec.amount = amount;
    return spec;
}

void addNoise(cv::Mat& image, const NoiseSpec& noise, std::uint64_t seed) {
    if (image.depth() != CV_8U) throw InvalidInput("noise: the image must be 8-bit");
    cv::RNG rng(seed);
    if (noise.kind == NoiseSpec::Kind::SaltPepper) {
        // A pixel is replaced as a whole (all channels), as a dead or saturated sensor pixel is.
        const double p = noise.amount / 100.0;
        for (int y = 0; y < image.rows; ++y) {
            auto* row = image.ptr<std::uint8_t>(y);
            for (int x = 0; x < image.cols; ++x) {
                const double u = rng.uniform(0.0, 1.0);
                if (u >= p) continue;
                const std::uint8_t value = u < p / 2.0 ? 0 : 255;
                for (int c = 0; c < image.channels(); ++c) row[x * image.channels() + c] = value;
            }
        }
    } else if (noise.kind == NoiseSpec::Kind::Gaussian) {
        cv::Mat gaussian(image.size(), CV_32FC(image.channels()));
        rng.fill(gaussian, cv::RNG::NORMAL, 0.0, noise.amount);
        cv::Mat sum;
        image.convertTo(sum, CV_32F);
        sum += gaussian;
        sum.convertTo(image, image.type());  // rounds and saturates to 0..255
    }
}

}  // namespace icewatch::stereo
