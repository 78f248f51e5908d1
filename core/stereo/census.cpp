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

void CensusImage::create(int w, int h, int wordsPerPixel, int firstStoredRow) {
    width = w;
    height = h;
    words = wordsPerPixel;
    first = 0;
    firstRow = firstStoredRow;
    storedWidth = w;
    resizeExactly(data, static_cast<std::size_t>(w) * h * wordsPerPixel);
}

// Integer derivatives are several times faster than float ones, and every test on them below is
// exact.
void sobel16(const cv::Mat& image, cv::Mat& dx, cv::Mat& dy) {
    cv::Sobel(image, dx, CV_16S, 1, 0, 3, 1.0, 0.0, cv::BORDER_REPLICATE);
    cv::Sobel(image, dy, CV_16S, 0, 1, 3, 1.0, 0.0, cv::BORDER_REPLICATE);
}

namespace {

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

cv::Mat censusWindowMask(const cv::Mat& grey, double gradientThreshold, EyeScratch* scratch) {
    CV_Assert(grey.type() == CV_8UC1);
    EyeScratch own;
    cv::Mat& dx = (scratch ? *scratch : own).dx;
    cv::Mat& dy = (scratch ? *scratch : own).dy;
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

cv::Mat channelGradientMagnitudes(const cv::Mat& bgr, EyeScratch* scratch) {
    CV_Assert(bgr.depth() == CV_8U);
    EyeScratch own;
    cv::Mat& dx = (scratch ? *scratch : own).colourDx;
    cv::Mat& dy = (scratch ? *scratch : own).colourDy;
    sobel16(bgr, dx, dy);
    // Quarter grey levels: the gradient term is decisive and needs the resolution; gradients above
    // 63.75 grey levels per pixel (strong edges, where Census and AD decide anyway) saturate.
    // sqrt((dx² + dy²) / 64) is exact up to the float square root's rounding, as the float Sobel
    // (scaled by 1/8) and cv::magnitude computed it.
    // The vector loop does the same float operations (squares summed exactly in 32-bit integers,
    // the exact 1/64, sqrt, round to nearest even, saturation), so it gives the same bytes.
    cv::Mat magnitude8(bgr.size(), CV_8UC(bgr.channels()));
    const int values = bgr.cols * bgr.channels();
    constexpr int kStep = cv::v_uint8::nlanes;  // values per iteration: 4 float vectors
    const int vectorEnd = values / kStep * kStep;
    const cv::v_float32 scale = cv::vx_setall_f32(1.0f / 64.0f), steps = cv::vx_setall_f32(kGradientSteps);
    auto magnitudes = [&](const cv::v_int16& x, const cv::v_int16& y) {
        cv::v_int32 x0, x1, y0, y1;
        cv::v_expand(x, x0, x1);
        cv::v_expand(y, y0, y1);
        const cv::v_int32 a = cv::v_round(cv::v_sqrt(cv::v_cvt_f32(x0 * x0 + y0 * y0) * scale) * steps);
        const cv::v_int32 b = cv::v_round(cv::v_sqrt(cv::v_cvt_f32(x1 * x1 + y1 * y1) * scale) * steps);
        return cv::v_pack(a, b);  // saturating to int16; magnitudes are far below its range
    };
    for (int y = 0; y < bgr.rows; ++y) {
        const auto* gx = dx.ptr<std::int16_t>(y);
        const auto* gy = dy.ptr<std::int16_t>(y);
        auto* out = magnitude8.ptr<std::uint8_t>(y);
        for (int i = 0; i < vectorEnd; i += kStep) {
            constexpr int kHalf = kStep / 2;
            const cv::v_int16 lo = magnitudes(cv::vx_load(gx + i), cv::vx_load(gy + i));
            const cv::v_int16 hi = magnitudes(cv::vx_load(gx + i + kHalf), cv::vx_load(gy + i + kHalf));
            cv::v_store(out + i, cv::v_pack_u(lo, hi));  // saturating to 0..255
        }
        for (int i = vectorEnd; i < values; ++i) {
            const float squared = static_cast<float>(gx[i] * gx[i] + gy[i] * gy[i]) * (1.0f / 64.0f);
            out[i] = cv::saturate_cast<std::uint8_t>(std::sqrt(squared) * static_cast<float>(kGradientSteps));
        }
    }
    return magnitude8;
}

namespace {

// Pixels coded at once, one vector lane each: 32 with AVX2, 16 with SSE or NEON.
constexpr int kChunk = cv::v_uint8::nlanes;
static_assert(kChunk == 16 || kChunk == 32, "the Census byte transpose handles 128- and 256-bit vectors");
constexpr int kBlock = 16;  // pixels per 128-bit block of a vector

// Window offsets in code order (row-major, centre skipped).
std::vector<cv::Point> windowOffsets(int radius) {
    std::vector<cv::Point> offsets;
    for (int dy = -radius; dy <= radius; ++dy)
        for (int dx = -radius; dx <= radius; ++dx)
            if (dx != 0 || dy != 0) offsets.emplace_back(dx, dy);
    return offsets;
}

// floor(x / D) for 0 <= x < 256 D (every up or down sum whose quotient is a grey level) as the high
// half of a 16-bit product shifted right: magic = ceil(2^(16 + shift) / D) with the smallest shift
// that is exact over the whole range, checked exhaustively at compile time.
constexpr bool divisionIsExact(int d, int magic, int shift) {
    for (int x = 0; x < 256 * d; ++x)
        if (((x * magic) >> 16 >> shift) != x / d) return false;
    return true;
}

template <int D>
struct Divider {
    static constexpr int shift = [] {
        for (int s = 0; s < 16; ++s) {
            const long long magic = ((1LL << (16 + s)) + D - 1) / D;
            if (magic < 65536 && divisionIsExact(D, static_cast<int>(magic), s)) return s;
        }
        return -1;
    }();
    static_assert(shift >= 0, "no exact 16-bit multiply-high division");
    static constexpr int magic = static_cast<int>(((1LL << (16 + shift)) + D - 1) / D);
};

// The sums, minima and maxima of the 7 and the 9 grey levels of every padded column around one
// row (rows -3 .. 3 and -4 .. 4): the first, vertical half of the window statistics. Sums of up to
// 81 grey levels fit 16 bits.
struct ColumnStats {
    std::vector<std::uint16_t> sum7, sum9;
    std::vector<std::uint8_t> min7, min9, max7, max9;

    void resize(int columns) {
        const auto n = static_cast<std::size_t>(columns);
        sum7.resize(n);
        sum9.resize(n);
        min7.resize(n);
        min9.resize(n);
        max7.resize(n);
        max9.resize(n);
    }
};

// Column statistics of padded columns [0, columns), a multiple of kChunk, around the padded row
// starting at `row`.
void columnStats(const std::uint8_t* row, std::ptrdiff_t step, int columns, ColumnStats& out) {
    constexpr int kHalf = cv::v_uint16::nlanes;
    for (int x = 0; x < columns; x += kChunk) {
        cv::v_uint8 r[9];
        for (int i = 0; i < 9; ++i) r[i] = cv::vx_load(row + (i - 4) * step + x);
        cv::v_uint8 lo = r[1], hi = r[1];
        cv::v_uint16 sum0, sum1;
        cv::v_expand(r[1], sum0, sum1);
        // Rows a .. b-1 into the running minimum, maximum and sum: the 7-row window, then the
        // 9-row one grows from it by its two outer rows.
        auto add = [&](int a, int b) {
            for (int i = a; i < b; ++i) {
                cv::v_uint16 e0, e1;
                lo = cv::v_min(lo, r[i]);
                hi = cv::v_max(hi, r[i]);
                cv::v_expand(r[i], e0, e1);
                sum0 = sum0 + e0;
                sum1 = sum1 + e1;
            }
        };
        add(2, 8);
        cv::v_store(out.min7.data() + x, lo);
        cv::v_store(out.max7.data() + x, hi);
        cv::v_store(out.sum7.data() + x, sum0);
        cv::v_store(out.sum7.data() + x + kHalf, sum1);
        add(0, 1);
        add(8, 9);
        cv::v_store(out.min9.data() + x, lo);
        cv::v_store(out.max9.data() + x, hi);
        cv::v_store(out.sum9.data() + x, sum0);
        cv::v_store(out.sum9.data() + x + kHalf, sum1);
    }
}

// A window's trimmed sum (two halves of 16-bit lanes) for the kChunk pixels from padded column x:
// the horizontal half, over the column statistics.
template <int Radius>
void trimmedSums(const std::uint16_t* sum, const std::uint8_t* lo8, const std::uint8_t* hi8, int x,
                 cv::v_uint16 trimmed[2]) {
    constexpr int kHalf = cv::v_uint16::nlanes;
    cv::v_uint16 s0 = cv::vx_load(sum + x - Radius), s1 = cv::vx_load(sum + x - Radius + kHalf);
    cv::v_uint8 lo = cv::vx_load(lo8 + x - Radius), hi = cv::vx_load(hi8 + x - Radius);
    for (int dx = 1 - Radius; dx <= Radius; ++dx) {
        s0 = s0 + cv::vx_load(sum + x + dx);
        s1 = s1 + cv::vx_load(sum + x + dx + kHalf);
        lo = cv::v_min(lo, cv::vx_load(lo8 + x + dx));
        hi = cv::v_max(hi, cv::vx_load(hi8 + x + dx));
    }
    cv::v_uint16 lo0, lo1, hi0, hi1;
    cv::v_expand(lo, lo0, lo1);
    cv::v_expand(hi, hi0, hi1);
    // The sum holds the minimum and the maximum: no saturation.
    trimmed[0] = s0 - lo0 - hi0;
    trimmed[1] = s1 - lo1 - hi1;
}

// The two thresholds of a window of Count + 2 values from trimmed sums, with the sign bit flipped
// (grey ^ 0x80): the encoder compares as signed bytes, one instruction on x86, where unsigned byte
// comparisons take three.
template <int Count>
class ThresholdMaths {
public:
    explicit ThresholdMaths(int alpha)
        : alpha_(alpha),
          // From alpha = 256 on every neighbour is inside the band (hi 255, lo 0); the clamp keeps
          // alpha * Count and the sums below within 16 bits.
          band_(cv::vx_setall_u16(static_cast<std::uint16_t>(std::clamp(alpha, 0, 256) * Count))),
          roundUp_(cv::vx_setall_u16(Count - 1)),
          limit_(cv::vx_setall_u16(256 * Count - 1)),  // quotient 255
          magic_(cv::vx_setall_u16(static_cast<std::uint16_t>(Divider<Count>::magic))) {}

    void operator()(const cv::v_uint16 trimmed[2], cv::v_int8& hi, cv::v_int8& lo) const {
        if (alpha_ < 0) {  // no use and no fast path: the plain formula
            scalar(trimmed, hi, lo);
            return;
        }
        // Saturating 16-bit arithmetic: up stays below 2^16; down saturates at 0 exactly where
        // the reference's ceiling is 0.
        cv::v_uint16 up[2], down[2];
        for (int h = 0; h < 2; ++h) {
            up[h] = divide(cv::v_min(trimmed[h] + band_, limit_));
            down[h] = divide(cv::v_min((trimmed[h] - band_) + roundUp_, limit_));
        }
        const cv::v_uint8 sign = cv::vx_setall_u8(0x80);
        hi = cv::v_reinterpret_as_s8(cv::v_pack(up[0], up[1]) ^ sign);
        lo = cv::v_reinterpret_as_s8(cv::v_pack(down[0], down[1]) ^ sign);
    }

private:
    cv::v_uint16 divide(const cv::v_uint16& v) const { return cv::v_mul_hi(v, magic_) >> Divider<Count>::shift; }

    void scalar(const cv::v_uint16 trimmed[2], cv::v_int8& hi, cv::v_int8& lo) const {
        constexpr int kHalf = cv::v_uint16::nlanes;
        std::uint16_t sums[kChunk];
        cv::v_store(sums, trimmed[0]);
        cv::v_store(sums + kHalf, trimmed[1]);
        std::int8_t his[kChunk], los[kChunk];
        for (int i = 0; i < kChunk; ++i) {
            const Thresholds t = thresholdsFor(sums[i], Count, alpha_);
            his[i] = static_cast<std::int8_t>(t.hi ^ 0x80);
            los[i] = static_cast<std::int8_t>(t.lo ^ 0x80);
        }
        hi = cv::vx_load(his);
        lo = cv::vx_load(los);
    }

    int alpha_;
    cv::v_uint16 band_, roundUp_, limit_, magic_;
};

// Interleaves the lanes of a and b within each 128-bit block. The transpose below needs no more
// (each block keeps its own 16 pixels throughout); AVX2's unpack instructions work so, whereas
// cv::v_zip on 256-bit vectors adds two lane-crossing permutes to every call.
template <class V>
void zipBlocks(const V& a, const V& b, V& ab0, V& ab1) {
#if CV_SIMD256
    cv::v256_zip(a, b, ab0, ab1);
#else
    cv::v_zip(a, b, ab0, ab1);
#endif
}

// The same for 64-bit lanes, which have no v_zip on 128-bit vectors: the low halves of the blocks
// of a and b, then the high halves.
void zipHalvesOfBlocks(const cv::v_uint32& a, const cv::v_uint32& b, cv::v_uint32& lows, cv::v_uint32& highs) {
#if CV_SIMD256
    cv::v_uint64 l, h;
    cv::v256_zip(cv::v_reinterpret_as_u64(a), cv::v_reinterpret_as_u64(b), l, h);
    lows = cv::v_reinterpret_as_u32(l);
    highs = cv::v_reinterpret_as_u32(h);
#else
    lows = cv::v_combine_low(a, b);
    highs = cv::v_combine_high(a, b);
#endif
}

// Stores the 16 bytes of one block of v (block 1: the upper half of a 256-bit vector).
void storeBlock(std::uint64_t* dst, const cv::v_uint8& v, int block) {
    auto* bytes = reinterpret_cast<std::uint8_t*>(dst);
    if constexpr (kChunk == kBlock) {
        cv::v_store(bytes, v);
    } else if (block == 0) {
        cv::v_store_low(bytes, v);
    } else {
        cv::v_store_high(bytes, v);
    }
}

// rows[j], lane i = byte j of the two words (16 bytes, little endian like the reference's shifts)
// of pixel i: four rounds of interleaving (8, 16, 32 and 64 bits) transpose each block of 16
// pixels, leaving each pixel's two words in one 128-bit block, stored to words[8 i + offset] (the
// pixel's words offset and offset + 1).
void storeWordPairs(const cv::v_uint8 rows[16], std::uint64_t* words, int offset) {
    cv::v_uint8 a[16];  // a[8h + k]: rows 2k, 2k + 1 of pixels 8h .. 8h + 7
    for (int k = 0; k < 8; ++k) zipBlocks(rows[2 * k], rows[2 * k + 1], a[k], a[8 + k]);
    cv::v_uint16 b[16];  // b[4q + m]: rows 4m .. 4m + 3 of pixels 4q .. 4q + 3
    for (int h = 0; h < 2; ++h)
        for (int m = 0; m < 4; ++m)
            zipBlocks(cv::v_reinterpret_as_u16(a[8 * h + 2 * m]), cv::v_reinterpret_as_u16(a[8 * h + 2 * m + 1]),
                      b[8 * h + m], b[8 * h + 4 + m]);
    cv::v_uint32 c[16];  // c[4q + 2h + n]: rows 8n .. 8n + 7 of pixels 4q + 2h, 4q + 2h + 1
    for (int q = 0; q < 4; ++q)
        for (int n = 0; n < 2; ++n)
            zipBlocks(cv::v_reinterpret_as_u32(b[4 * q + 2 * n]), cv::v_reinterpret_as_u32(b[4 * q + 2 * n + 1]),
                      c[4 * q + n], c[4 * q + 2 + n]);
    for (int r = 0; r < 8; ++r) {  // rows 0 .. 15 of pixels 2r, 2r + 1
        cv::v_uint32 d[2];
        zipHalvesOfBlocks(c[2 * r], c[2 * r + 1], d[0], d[1]);
        for (int block = 0; block < kChunk / kBlock; ++block)
            for (int e = 0; e < 2; ++e)
                storeBlock(words + kImprovedCensusWords * (kBlock * block + 2 * r + e) + offset,
                           cv::v_reinterpret_as_u8(d[e]), block);
    }
}

// ec << 4, by a 16-bit shift: the values are below 16, no bit crosses into the next byte.
cv::Mat shiftedToHighNibble(const cv::Mat& ec) {
    cv::Mat high(ec.size(), CV_8UC1);
    for (int y = 0; y < ec.rows; ++y) {
        const std::uint8_t* s = ec.ptr<std::uint8_t>(y);
        std::uint8_t* d = high.ptr<std::uint8_t>(y);
        int x = 0;
        for (; x + kChunk <= ec.cols; x += kChunk)
            cv::v_store(d + x, cv::v_reinterpret_as_u8(cv::v_reinterpret_as_u16(cv::vx_load(s + x)) << 4));
        for (; x < ec.cols; ++x) d[x] = static_cast<std::uint8_t>(s[x] << 4);
    }
    return high;
}

// One window's thresholds for a chunk's pixels and which of them want its code.
struct WindowChunk {
    cv::v_int8 hi, lo;  // sign bit flipped
    cv::v_uint8 need;   // 0xFF where the pixel wants the code (masked images only)
    bool any;
};

// A chunk's centre pixels in the padded images.
struct ChunkCentre {
    const std::int8_t* grey;
    const std::uint8_t* ec;
    const std::uint8_t* ecHigh;
};

// Byte j of a code word for a chunk: the nibbles of neighbours a (low) and b (high), byte offsets
// from the centre pixels.
template <bool Masked>
cv::v_uint8 codeByte(const ChunkCentre& at, int a, int b, const WindowChunk& w) {
    const cv::v_int8 brighterLow = cv::vx_setall_s8(0x08), darkerLow = cv::vx_setall_s8(0x04);
    const cv::v_int8 brighterHigh = cv::vx_setall_s8(static_cast<std::int8_t>(0x80));
    const cv::v_int8 darkerHigh = cv::vx_setall_s8(0x40);
    const cv::v_int8 ga = cv::vx_load(at.grey + a), gb = cv::vx_load(at.grey + b);
    const cv::v_int8 compared = ((ga > w.hi) & brighterLow) | ((w.lo > ga) & darkerLow) |
                                ((gb > w.hi) & brighterHigh) | ((w.lo > gb) & darkerHigh);
    const cv::v_uint8 bits = cv::v_reinterpret_as_u8(compared) | cv::vx_load(at.ec + a) | cv::vx_load(at.ecHigh + b);
    if constexpr (Masked) return bits & w.need;
    return bits;
}

// The codes of kChunk pixels, to words[kImprovedCensusWords i ..] for pixel i. offsets: the byte
// offsets of the 7x7 window's neighbours then the 9x9 window's, in code order (16 per word: those
// of word k of a pixel's eight). Pixels that do not want a window get zeros, as in the reference;
// word pairs no pixel wants are not coded.
template <bool Masked>
void encodeChunk(const ChunkCentre& at, const int* offsets, const WindowChunk& w7,
                 const WindowChunk& w9, std::uint64_t* words) {
    static_assert(kCensus7Offset == 0 && kCensus9Offset == kCensus7Words &&
                  kImprovedCensusWords == kCensus7Words + kCensus9Words && kImprovedCensusWords % 2 == 0);
    for (int pair = 0; pair < kImprovedCensusWords / 2; ++pair) {
        cv::v_uint8 rows[16];
        bool any = false;
        for (int half = 0; half < 2; ++half) {
            const int word = 2 * pair + half;
            const WindowChunk& w = word < kCensus9Offset ? w7 : w9;
            const int* k = offsets + 16 * word;
            for (int j = 0; j < 8; ++j)
                rows[8 * half + j] = w.any ? codeByte<Masked>(at, k[2 * j], k[2 * j + 1], w) : cv::vx_setzero_u8();
            any |= w.any;
        }
        if (any) {
            storeWordPairs(rows, words, 2 * pair);
        } else {
            for (int i = 0; i < kChunk; ++i) std::fill_n(words + kImprovedCensusWords * i + 2 * pair, 2, 0);
        }
    }
}

}  // namespace

void CensusEncoder::prepareImproved(const cv::Mat& grey, const cv::Mat& edgeCorner, int alpha,
                                    const cv::Mat& windowMask) {
    CV_Assert(grey.type() == CV_8UC1 && edgeCorner.type() == CV_8UC1 && grey.size() == edgeCorner.size());
    CV_Assert(windowMask.empty() || (windowMask.type() == CV_8UC1 && windowMask.size() == grey.size()));
    improved_ = true;
    size_ = grey.size();
    alpha_ = alpha;
    windowMask_ = windowMask;
    // Extra columns on the right so the last chunk of a row, its window statistics included, can
    // load whole vectors.
    cv::copyMakeBorder(grey, padded_, kPad, kPad, kPad, kPad + 2 * kChunk, cv::BORDER_REPLICATE);
    cv::copyMakeBorder(edgeCorner, ec_, kPad, kPad, kPad, kPad + 2 * kChunk, cv::BORDER_REPLICATE);
    ecHigh_ = shiftedToHighNibble(ec_);
    cv::bitwise_xor(padded_, cv::Scalar::all(0x80), signedGrey_);
    CV_Assert(padded_.step == signedGrey_.step && signedGrey_.step == ec_.step && ec_.step == ecHigh_.step);
    const std::ptrdiff_t step = static_cast<std::ptrdiff_t>(signedGrey_.step);
    offsets_.clear();
    for (int radius : {3, 4})
        for (const cv::Point& o : windowOffsets(radius)) offsets_.push_back(static_cast<int>(o.y * step + o.x));
}

void CensusEncoder::prepareMei(const cv::Mat& grey) {
    CV_Assert(grey.type() == CV_8UC1);
    improved_ = false;
    size_ = grey.size();
    cv::copyMakeBorder(grey, padded_, 3, 3, 4, 4, cv::BORDER_REPLICATE);
}

int CensusEncoder::words() const { return improved_ ? kImprovedCensusWords : 1; }

void CensusEncoder::encodeRows(int begin, int end, CensusImage& out) const {
    CV_Assert(0 <= begin && begin <= end && end <= size_.height);
    out.create(size_.width, end - begin, words(), begin);
    forEachStripe(end - begin, [&](int, int stripeBegin, int stripeEnd) {
        encodeInto(begin + stripeBegin, begin + stripeEnd, out);
    });
}

void CensusEncoder::encodeRowsHere(int begin, int end, CensusImage& out) const {
    CV_Assert(0 <= begin && begin <= end && end <= size_.height);
    out.create(size_.width, end - begin, words(), begin);
    encodeInto(begin, end, out);
}

void CensusEncoder::encodeInto(int begin, int end, CensusImage& out) const {
    if (improved_) {
        encodeImprovedRows(begin, end, out);
    } else {
        encodeMeiRows(begin, end, out);
    }
}

void CensusEncoder::encodeImprovedRows(int rowBegin, int rowEnd, CensusImage& out) const {
    const int cols = size_.width;
    const std::ptrdiff_t step = static_cast<std::ptrdiff_t>(signedGrey_.step);
    // Padded columns the chunks' windows cover.
    const int statColumns = (cols + kChunk - 1) / kChunk * kChunk + kChunk;
    CV_Assert(statColumns <= padded_.cols);
    const bool masked = !windowMask_.empty();
    // Window sums, minima and maxima per row, vertical then horizontal, in 16- and 8-bit vectors:
    // several times fewer instructions than box filters, erosions and dilations of the whole
    // image, and no images of them. Kept per thread: the cost stage codes a row at a time.
    thread_local ColumnStats stats;
    stats.resize(statColumns);
    const ThresholdMaths<47> thresholds7(alpha_);
    const ThresholdMaths<79> thresholds9(alpha_);
    std::uint64_t tail[kChunk * kImprovedCensusWords];  // the last, partial chunk of a row
    const cv::v_uint8 all = cv::vx_setall_u8(0xFF), none = cv::vx_setzero_u8();
    for (int y = rowBegin; y < rowEnd; ++y) {
        columnStats(padded_.ptr<std::uint8_t>(y + kPad), step, statColumns, stats);
        const std::uint8_t* mask = masked ? windowMask_.ptr<std::uint8_t>(y) : nullptr;
        const std::ptrdiff_t rowCentre = (y + kPad) * step + kPad;
        const ChunkCentre rowStart{signedGrey_.ptr<std::int8_t>() + rowCentre, ec_.ptr<std::uint8_t>() + rowCentre,
                                   ecHigh_.ptr<std::uint8_t>() + rowCentre};
        for (int x0 = 0; x0 < cols; x0 += kChunk) {
            const int count = std::min(kChunk, cols - x0);
            const ChunkCentre at{rowStart.grey + x0, rowStart.ec + x0, rowStart.ecHigh + x0};
            std::uint64_t* words = count == kChunk ? out.at(x0, y) : tail;
            cv::v_uint16 trimmed[2];
            WindowChunk w7{cv::vx_setzero_s8(), cv::vx_setzero_s8(), all, true};
            WindowChunk w9 = w7;
            if (masked) {
                // (Lanes past the end of a row may want either window: they are not stored.)
                std::uint8_t partial[kChunk] = {};
                if (count < kChunk) std::copy_n(mask + x0, count, partial);
                w7.need = cv::vx_load(count == kChunk ? mask + x0 : partial) != none;
                w9.need = ~w7.need;
                w7.any = cv::v_check_any(w7.need);
                w9.any = cv::v_check_any(w9.need);
            }
            if (w7.any) {
                trimmedSums<3>(stats.sum7.data(), stats.min7.data(), stats.max7.data(), x0 + kPad, trimmed);
                thresholds7(trimmed, w7.hi, w7.lo);
            }
            if (w9.any) {
                trimmedSums<4>(stats.sum9.data(), stats.min9.data(), stats.max9.data(), x0 + kPad, trimmed);
                thresholds9(trimmed, w9.hi, w9.lo);
            }
            if (masked) {
                encodeChunk<true>(at, offsets_.data(), w7, w9, words);
            } else {
                encodeChunk<false>(at, offsets_.data(), w7, w9, words);
            }
            if (words == tail) std::copy_n(tail, count * kImprovedCensusWords, out.at(x0, y));
        }
    }
}

void CensusEncoder::encodeMeiRows(int rowBegin, int rowEnd, CensusImage& out) const {
    for (int y = rowBegin; y < rowEnd; ++y)
        for (int x = 0; x < size_.width; ++x) {
            const int centre = padded_.at<std::uint8_t>(y + 3, x + 4);
            std::uint64_t code = 0;
            for (int dy = -3; dy <= 3; ++dy) {
                const std::uint8_t* row = padded_.ptr<std::uint8_t>(y + 3 + dy) + x + 4;
                for (int dx = -4; dx <= 4; ++dx) {
                    if (dx == 0 && dy == 0) continue;
                    code = (code << 1) | static_cast<std::uint64_t>(row[dx] < centre);
                }
            }
            *out.at(x, y) = code;
        }
}

void improvedCensus(const cv::Mat& grey, const cv::Mat& edgeCorner, int alpha, const cv::Mat& windowMask,
                    CensusImage& out) {
    CensusEncoder encoder;
    encoder.prepareImproved(grey, edgeCorner, alpha, windowMask);
    encoder.encodeRows(0, grey.rows, out);
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
    CensusEncoder encoder;
    encoder.prepareMei(grey);
    encoder.encodeRows(0, grey.rows, out);
}

}  // namespace icewatch::stereo::detail
