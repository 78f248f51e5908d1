// Census transforms.
//
// Improved Census (Wei et al. 2025, section "matching cost"): the reference of a window is not
// its centre pixel but the mean of the window after dropping its largest and smallest grey value
// (one noisy centre no longer flips every bit), each neighbour gives two bits with a ±alpha
// "no change" band (noise of a few grey levels gives 00 on both sides instead of random bits), and
// the window is 7x7 on textured pixels (gradient > T) but 9x9 on flat ones, where more support is
// needed. Canny edge and Harris corner flags of the neighbour complete the four-bit code.
//
// The comparisons are exact integer ones: with S the trimmed sum and m = n - 2 values left,
// I > S/m + alpha  <=>  I > floor((S + alpha m) / m), and I < S/m - alpha  <=>  I < ceil((S - alpha m) / m),
// so every pixel gets two 8-bit thresholds and no floating point is involved.
#include <algorithm>
#include <bit>
#include <cmath>

#include "core/common/simd.hpp"
#include <opencv2/imgproc.hpp>

#include "core/stereo/stages.hpp"

namespace icewatch::stereo::detail {

void CensusImage::create(int w, int h, int wordsPerPixel) {
    width = w;
    height = h;
    words = wordsPerPixel;
    data.resize(static_cast<std::size_t>(w) * h * wordsPerPixel);
}

namespace {

// 3x3 Sobel derivatives of an 8-bit image (any channel count), exact in 16 bits. Sobel / 8 is the
// slope in grey levels per pixel on a ramp, with the usual 3x3 smoothing. Integer derivatives are
// several times faster than float ones, and every test on them below is exact.
void sobel16(const cv::Mat& image, cv::Mat& dx, cv::Mat& dy) {
    cv::Sobel(image, dx, CV_16S, 1, 0, 3, 1.0, 0.0, cv::BORDER_REPLICATE);
    cv::Sobel(image, dy, CV_16S, 0, 1, 3, 1.0, 0.0, cv::BORDER_REPLICATE);
}

struct Thresholds {
    std::uint8_t hi;  // brighter than ref + alpha  <=>  I > hi
    std::uint8_t lo;  // darker than ref - alpha    <=>  I < lo
};

Thresholds thresholdsFor(int trimmedSum, int count, int alpha) {
    const int up = trimmedSum + alpha * count;                      // >= 0
    const int down = trimmedSum - alpha * count;
    const int hi = std::min(255, up / count);                        // floor
    const int lo = down <= 0 ? 0 : std::min(255, (down + count - 1) / count);  // ceil
    return {static_cast<std::uint8_t>(hi), static_cast<std::uint8_t>(lo)};
}

std::uint64_t nibble(int value, Thresholds t, int edgeCorner) {
    return static_cast<std::uint64_t>(((value > t.hi) << 3) | ((value < t.lo) << 2) | edgeCorner);
}

// One window's code for the pixel at padded position (px, py); radius 3 or 4.
template <int Radius>
void encodeWindow(const cv::Mat& paddedGrey, const cv::Mat& paddedEc, int px, int py, Thresholds t,
                  std::uint64_t* words) {
    constexpr int kWords = Radius == 3 ? kCensus7Words : kCensus9Words;
    std::uint64_t acc[kWords] = {};
    int k = 0;
    for (int dy = -Radius; dy <= Radius; ++dy) {
        const std::uint8_t* g = paddedGrey.ptr<std::uint8_t>(py + dy) + px;
        const std::uint8_t* e = paddedEc.ptr<std::uint8_t>(py + dy) + px;
        for (int dx = -Radius; dx <= Radius; ++dx) {
            if (dx == 0 && dy == 0) continue;
            acc[k >> 4] |= nibble(g[dx], t, e[dx]) << (4 * (k & 15));
            ++k;
        }
    }
    std::copy(acc, acc + kWords, words);
}

// Trimmed sum, minimum and maximum of a window the slow, obvious way.
int trimmedSumAt(const cv::Mat& paddedGrey, int px, int py, int radius) {
    int sum = 0, lo = 255, hi = 0;
    for (int dy = -radius; dy <= radius; ++dy)
        for (int dx = -radius; dx <= radius; ++dx) {
            const int v = paddedGrey.at<std::uint8_t>(py + dy, px + dx);
            sum += v;
            lo = std::min(lo, v);
            hi = std::max(hi, v);
        }
    return sum - lo - hi;
}

constexpr int kPad = 4;

}  // namespace

cv::Mat censusWindowMask(const cv::Mat& grey, double gradientThreshold) {
    CV_Assert(grey.type() == CV_8UC1);
    cv::Mat dx, dy;
    sobel16(grey, dx, dy);
    // |∇I| / 8 > T  <=>  dx² + dy² > (8T)², compared exactly on the integer squares.
    const double limit = 64.0 * gradientThreshold * std::abs(gradientThreshold);
    cv::Mat mask(grey.size(), CV_8UC1);
    for (int y = 0; y < grey.rows; ++y) {
        const auto* gx = dx.ptr<std::int16_t>(y);
        const auto* gy = dy.ptr<std::int16_t>(y);
        auto* out = mask.ptr<std::uint8_t>(y);
        for (int x = 0; x < grey.cols; ++x) {
            const int squared = gx[x] * gx[x] + gy[x] * gy[x];
            out[x] = static_cast<double>(squared) > limit ? 1 : 0;
        }
    }
    return mask;
}

cv::Mat channelGradientMagnitudes(const cv::Mat& bgr) {
    CV_Assert(bgr.depth() == CV_8U);
    cv::Mat dx, dy;
    sobel16(bgr, dx, dy);
    // Quarter grey levels: the gradient term is decisive and needs the resolution; gradients above
    // 63.75 grey levels per pixel (strong edges, where Census and AD decide anyway) saturate.
    // sqrt((dx² + dy²) / 64) is exact up to the float square root's rounding, as the float Sobel
    // (scaled by 1/8) and cv::magnitude computed it.
    cv::Mat magnitude8(bgr.size(), CV_8UC(bgr.channels()));
    const int values = bgr.cols * bgr.channels();
    for (int y = 0; y < bgr.rows; ++y) {
        const auto* gx = dx.ptr<std::int16_t>(y);
        const auto* gy = dy.ptr<std::int16_t>(y);
        auto* out = magnitude8.ptr<std::uint8_t>(y);
        for (int i = 0; i < values; ++i) {
            const float squared = static_cast<float>(gx[i] * gx[i] + gy[i] * gy[i]) * (1.0f / 64.0f);
            out[i] = cv::saturate_cast<std::uint8_t>(std::sqrt(squared) * static_cast<float>(kGradientSteps));
        }
    }
    return magnitude8;
}

cv::Mat edgeCornerBits(const cv::Mat& grey, const Parameters& parameters) {
    CV_Assert(grey.type() == CV_8UC1);
    // One pair of derivatives serves both detectors: Canny's own (3x3 Sobel, replicated border)
    // and Harris' (the same Sobel; its scale does not matter, the threshold is relative to the
    // largest response).
    cv::Mat dx, dy;
    sobel16(grey, dx, dy);
    cv::Mat edges;
    cv::Canny(dx, dy, edges, parameters.cannyLowThreshold, parameters.cannyHighThreshold, true);
    // Harris, k = 0.04 over 3x3 blocks: the products of the derivatives are integers, and so
    // are their 3x3 sums (below 2^24, exact in float); the response is taken in double.
    cv::Mat products(grey.size(), CV_32FC3);
    for (int y = 0; y < grey.rows; ++y) {
        const auto* gx = dx.ptr<std::int16_t>(y);
        const auto* gy = dy.ptr<std::int16_t>(y);
        auto* out = products.ptr<float>(y);
        for (int x = 0; x < grey.cols; ++x) {
            out[3 * x] = static_cast<float>(gx[x] * gx[x]);
            out[3 * x + 1] = static_cast<float>(gx[x] * gy[x]);
            out[3 * x + 2] = static_cast<float>(gy[x] * gy[x]);
        }
    }
    cv::boxFilter(products, products, CV_32F, {3, 3}, {-1, -1}, false, cv::BORDER_REPLICATE);
    cv::Mat response(grey.size(), CV_64FC1);
    double maxResponse = 0.0;
    for (int y = 0; y < grey.rows; ++y) {
        const auto* m = products.ptr<float>(y);
        auto* out = response.ptr<double>(y);
        for (int x = 0; x < grey.cols; ++x) {
            const double a = m[3 * x], b = m[3 * x + 1], c = m[3 * x + 2];
            out[x] = a * c - b * b - 0.04 * (a + c) * (a + c);
            maxResponse = std::max(maxResponse, out[x]);
        }
    }
    const double cornerLimit = parameters.harrisThreshold * maxResponse;
    cv::Mat bits(grey.size(), CV_8UC1);
    for (int y = 0; y < grey.rows; ++y) {
        const auto* e = edges.ptr<std::uint8_t>(y);
        const auto* r = response.ptr<double>(y);
        auto* out = bits.ptr<std::uint8_t>(y);
        for (int x = 0; x < grey.cols; ++x) {
            const bool corner = maxResponse > 0.0 && r[x] > cornerLimit;
            out[x] = static_cast<std::uint8_t>((e[x] != 0 ? 2 : 0) + (corner ? 1 : 0));
        }
    }
    return bits;
}

namespace {

constexpr int kChunk = cv::v_uint8x16::nlanes;  // pixels coded at once

// Window offsets in code order (row-major, centre skipped).
std::vector<cv::Point> windowOffsets(int radius) {
    std::vector<cv::Point> offsets;
    for (int dy = -radius; dy <= radius; ++dy)
        for (int dx = -radius; dx <= radius; ++dx)
            if (dx != 0 || dy != 0) offsets.emplace_back(dx, dy);
    return offsets;
}

// rows[j], lane i = byte j of pixel i's word: a 8x16 byte transpose by three rounds of
// interleaving gives each pixel's 8 bytes as one 64-bit lane (little endian, like the reference's
// shifts).
void transposeToWords(const cv::v_uint8x16 rows[8], std::uint64_t words[kChunk]) {
    static_assert(std::endian::native == std::endian::little, "the Census byte transpose assumes little endian");
    cv::v_uint8x16 a0, a1, b0, b1, c0, c1, d0, d1;
    cv::v_zip(rows[0], rows[1], a0, a1);
    cv::v_zip(rows[2], rows[3], b0, b1);
    cv::v_zip(rows[4], rows[5], c0, c1);
    cv::v_zip(rows[6], rows[7], d0, d1);
    cv::v_uint16x8 e[4], f[4];
    cv::v_zip(cv::v_reinterpret_as_u16(a0), cv::v_reinterpret_as_u16(b0), e[0], e[1]);
    cv::v_zip(cv::v_reinterpret_as_u16(a1), cv::v_reinterpret_as_u16(b1), e[2], e[3]);
    cv::v_zip(cv::v_reinterpret_as_u16(c0), cv::v_reinterpret_as_u16(d0), f[0], f[1]);
    cv::v_zip(cv::v_reinterpret_as_u16(c1), cv::v_reinterpret_as_u16(d1), f[2], f[3]);
    for (int i = 0; i < 4; ++i) {
        cv::v_uint32x4 lo, hi;
        cv::v_zip(cv::v_reinterpret_as_u32(e[i]), cv::v_reinterpret_as_u32(f[i]), lo, hi);
        cv::v_store(words + 4 * i, cv::v_reinterpret_as_u64(lo));
        cv::v_store(words + 4 * i + 2, cv::v_reinterpret_as_u64(hi));
    }
}

struct PaddedInputs {
    cv::Mat grey, ec, ecHigh;  // ecHigh = ec << 4, for the odd nibble of each byte
};

// The codes of one window for kChunk pixels starting at padded column px0 of padded row py.
// needed[i] says which pixels want this window; the others get zeros, as in the reference.
void encodeChunk(const PaddedInputs& in, int px0, int py, const std::vector<cv::Point>& offsets,
                 const std::uint8_t* hi, const std::uint8_t* lo, const bool* needed, int count,
                 std::uint64_t* const* pixelWords) {
    const cv::v_uint8x16 vHi = cv::v_load(hi), vLo = cv::v_load(lo);
    const cv::v_uint8x16 brighterLow = cv::v_setall_u8(0x08), darkerLow = cv::v_setall_u8(0x04);
    const cv::v_uint8x16 brighterHigh = cv::v_setall_u8(0x80), darkerHigh = cv::v_setall_u8(0x40);
    const int words = static_cast<int>(offsets.size()) / 16;
    for (int w = 0; w < words; ++w) {
        cv::v_uint8x16 rows[8];
        for (int j = 0; j < 8; ++j) {
            const cv::Point a = offsets[static_cast<std::size_t>(16 * w + 2 * j)];
            const cv::Point b = offsets[static_cast<std::size_t>(16 * w + 2 * j + 1)];
            const cv::v_uint8x16 ga = cv::v_load(in.grey.ptr<std::uint8_t>(py + a.y) + px0 + a.x);
            const cv::v_uint8x16 gb = cv::v_load(in.grey.ptr<std::uint8_t>(py + b.y) + px0 + b.x);
            const cv::v_uint8x16 low = ((ga > vHi) & brighterLow) | ((ga < vLo) & darkerLow) |
                                       cv::v_load(in.ec.ptr<std::uint8_t>(py + a.y) + px0 + a.x);
            const cv::v_uint8x16 high = ((gb > vHi) & brighterHigh) | ((gb < vLo) & darkerHigh) |
                                        cv::v_load(in.ecHigh.ptr<std::uint8_t>(py + b.y) + px0 + b.x);
            rows[j] = low | high;
        }
        std::uint64_t chunkWords[kChunk];
        transposeToWords(rows, chunkWords);
        for (int i = 0; i < count; ++i) pixelWords[i][w] = needed[i] ? chunkWords[i] : 0;
    }
}

}  // namespace

void improvedCensus(const cv::Mat& grey, const cv::Mat& edgeCorner, int alpha, const cv::Mat& windowMask,
                    CensusImage& out) {
    CV_Assert(grey.type() == CV_8UC1 && edgeCorner.type() == CV_8UC1 && grey.size() == edgeCorner.size());
    out.create(grey.cols, grey.rows, kImprovedCensusWords);
    // Extra columns on the right so the last chunk of a row can load whole vectors.
    PaddedInputs in;
    cv::copyMakeBorder(grey, in.grey, kPad, kPad, kPad, kPad + kChunk, cv::BORDER_REPLICATE);
    cv::copyMakeBorder(edgeCorner, in.ec, kPad, kPad, kPad, kPad + kChunk, cv::BORDER_REPLICATE);
    in.ecHigh = in.ec * 16;
    // Window sums by box filter, minima and maxima by erosion and dilation: vectorised in OpenCV.
    cv::Mat sum7, sum9, min7, min9, max7, max9;
    cv::boxFilter(in.grey, sum7, CV_32S, {7, 7}, {-1, -1}, false, cv::BORDER_REPLICATE);
    cv::boxFilter(in.grey, sum9, CV_32S, {9, 9}, {-1, -1}, false, cv::BORDER_REPLICATE);
    const cv::Mat box7 = cv::getStructuringElement(cv::MORPH_RECT, {7, 7});
    const cv::Mat box9 = cv::getStructuringElement(cv::MORPH_RECT, {9, 9});
    cv::erode(in.grey, min7, box7, {-1, -1}, 1, cv::BORDER_REPLICATE);
    cv::erode(in.grey, min9, box9, {-1, -1}, 1, cv::BORDER_REPLICATE);
    cv::dilate(in.grey, max7, box7, {-1, -1}, 1, cv::BORDER_REPLICATE);
    cv::dilate(in.grey, max9, box9, {-1, -1}, 1, cv::BORDER_REPLICATE);
    const std::vector<cv::Point> offsets7 = windowOffsets(3), offsets9 = windowOffsets(4);
    const bool both = windowMask.empty();
    forEachStripe(grey.rows, [&](int, int begin, int end) {
        std::uint8_t hi7[kChunk], lo7[kChunk], hi9[kChunk], lo9[kChunk];
        bool needs7[kChunk], needs9[kChunk];
        std::uint64_t* words7[kChunk];
        std::uint64_t* words9[kChunk];
        for (int y = begin; y < end; ++y) {
            const int py = y + kPad;
            const std::uint8_t* mask = both ? nullptr : windowMask.ptr<std::uint8_t>(y);
            for (int x0 = 0; x0 < grey.cols; x0 += kChunk) {
                const int count = std::min(kChunk, grey.cols - x0);
                bool any7 = false, any9 = false;
                for (int i = 0; i < kChunk; ++i) {
                    const int px = std::min(x0 + i, grey.cols - 1) + kPad;
                    const Thresholds t7 = thresholdsFor(
                        sum7.at<int>(py, px) - min7.at<std::uint8_t>(py, px) - max7.at<std::uint8_t>(py, px), 47, alpha);
                    const Thresholds t9 = thresholdsFor(
                        sum9.at<int>(py, px) - min9.at<std::uint8_t>(py, px) - max9.at<std::uint8_t>(py, px), 79, alpha);
                    hi7[i] = t7.hi;
                    lo7[i] = t7.lo;
                    hi9[i] = t9.hi;
                    lo9[i] = t9.lo;
                    if (i < count) {
                        needs7[i] = both || mask[x0 + i] != 0;
                        needs9[i] = both || mask[x0 + i] == 0;
                        any7 |= needs7[i];
                        any9 |= needs9[i];
                        words7[i] = out.at(x0 + i, y) + kCensus7Offset;
                        words9[i] = out.at(x0 + i, y) + kCensus9Offset;
                    }
                }
                if (any7) {
                    encodeChunk(in, x0 + kPad, py, offsets7, hi7, lo7, needs7, count, words7);
                } else {
                    for (int i = 0; i < count; ++i) std::fill(words7[i], words7[i] + kCensus7Words, 0);
                }
                if (any9) {
                    encodeChunk(in, x0 + kPad, py, offsets9, hi9, lo9, needs9, count, words9);
                } else {
                    for (int i = 0; i < count; ++i) std::fill(words9[i], words9[i] + kCensus9Words, 0);
                }
            }
        }
    });
}

void improvedCensusReference(const cv::Mat& grey, const cv::Mat& edgeCorner, int alpha, const cv::Mat& windowMask,
                             CensusImage& out) {
    out.create(grey.cols, grey.rows, kImprovedCensusWords);
    cv::Mat paddedGrey, paddedEc;
    cv::copyMakeBorder(grey, paddedGrey, kPad, kPad, kPad, kPad, cv::BORDER_REPLICATE);
    cv::copyMakeBorder(edgeCorner, paddedEc, kPad, kPad, kPad, kPad, cv::BORDER_REPLICATE);
    for (int y = 0; y < grey.rows; ++y)
        for (int x = 0; x < grey.cols; ++x) {
            std::uint64_t* words = out.at(x, y);
            std::fill(words, words + kImprovedCensusWords, 0);
            const bool use7 = windowMask.empty() || windowMask.at<std::uint8_t>(y, x) != 0;
            const bool use9 = windowMask.empty() || windowMask.at<std::uint8_t>(y, x) == 0;
            if (use7) {
                const Thresholds t = thresholdsFor(trimmedSumAt(paddedGrey, x + kPad, y + kPad, 3), 47, alpha);
                encodeWindow<3>(paddedGrey, paddedEc, x + kPad, y + kPad, t, words + kCensus7Offset);
            }
            if (use9) {
                const Thresholds t = thresholdsFor(trimmedSumAt(paddedGrey, x + kPad, y + kPad, 4), 79, alpha);
                encodeWindow<4>(paddedGrey, paddedEc, x + kPad, y + kPad, t, words + kCensus9Offset);
            }
        }
}

void meiCensus(const cv::Mat& grey, CensusImage& out) {
    CV_Assert(grey.type() == CV_8UC1);
    out.create(grey.cols, grey.rows, 1);
    cv::Mat padded;
    cv::copyMakeBorder(grey, padded, 3, 3, 4, 4, cv::BORDER_REPLICATE);
    forEachStripe(grey.rows, [&](int, int begin, int end) {
        for (int y = begin; y < end; ++y)
            for (int x = 0; x < grey.cols; ++x) {
                const int centre = padded.at<std::uint8_t>(y + 3, x + 4);
                std::uint64_t code = 0;
                for (int dy = -3; dy <= 3; ++dy) {
                    const std::uint8_t* row = padded.ptr<std::uint8_t>(y + 3 + dy) + x + 4;
                    for (int dx = -4; dx <= 4; ++dx) {
                        if (dx == 0 && dy == 0) continue;
                        code = (code << 1) | static_cast<std::uint64_t>(row[dx] < centre);
                    }
                }
                *out.at(x, y) = code;
            }
    });
}

}  // namespace icewatch::stereo::detail
