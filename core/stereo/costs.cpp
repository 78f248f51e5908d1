// Per-pixel matching costs, fused into one 16-bit fixed-point volume.
//
// Every term is robustified as 1 - exp(-C / λ) (the seed paper's fusion, after Mei et al.), so no
// single feature dominates and the sum stays in [0, terms). The exponentials are lookup tables
// indexed by the integer raw cost, built once per compute().
//
// The optimised kernel reverses the right row so that the right pixels x - d, d = 0, 1, ... are
// contiguous: the absolute differences of colour and gradient then run a vector of disparities at
// a time (OpenCV universal intrinsics: 32 with AVX2, 16 with SSE or NEON), and so does turning
// them into the index of one table holding both terms. The Census popcounts and the table lookups
// stay scalar: the CPUs it runs on have a fast scalar popcount, and a vector gather is no faster
// than scalar loads from tables this small.
#include <algorithm>
#include <bit>
#include <cmath>
#include <utility>

#include "core/common/simd.hpp"

#include "core/stereo/stages.hpp"

namespace icewatch::stereo::detail {

void CostVolume::create(int w, int h, int d) {
    width = w;
    height = h;
    disparities = d;
    stride = paddedDisparities(d);
    resizeExactly(data, static_cast<std::size_t>(w) * h * stride);
}

namespace {

std::vector<std::uint16_t> robustTable(int size, double rawPerIndex, double lambda) {
    std::vector<std::uint16_t> table(static_cast<std::size_t>(size));
    for (int i = 0; i < size; ++i) {
        table[static_cast<std::size_t>(i)] =
            static_cast<std::uint16_t>(std::lround(kCostScale * (1.0 - std::exp(-i * rawPerIndex / lambda))));
    }
    return table;
}

constexpr int kVec8 = cv::v_uint8::nlanes;  // the widest vector: 32 with AVX2, 16 with SSE or NEON
static_assert(kDisparityAlign % cv::v_uint16::nlanes == 0, "a cell holds whole 16-bit vectors");

// Planar copies of a row, reversed, with kVec8 zero bytes after the end for whole-vector loads.
struct ReversedRow {
    std::vector<std::uint8_t> planes[6];

    void fill(const cv::Mat& bgr, const cv::Mat& gradient, int y, int width) {
        // Sized once per stripe; the padding stays zero.
        const auto size = static_cast<std::size_t>(width + kVec8);
        for (auto& plane : planes)
            if (plane.size() != size) plane.assign(size, 0);
        reverse(bgr.ptr<cv::Vec3b>(y), width, planes);
        if (!gradient.empty()) reverse(gradient.ptr<cv::Vec3b>(y), width, planes + 3);
    }
    static void reverse(const cv::Vec3b* row, int width, std::vector<std::uint8_t>* out) {
        std::uint8_t* p0 = out[0].data() + width - 1;
        std::uint8_t* p1 = out[1].data() + width - 1;
        std::uint8_t* p2 = out[2].data() + width - 1;
        for (int x = 0; x < width; ++x) {
            p0[-x] = row[x][0];
            p1[-x] = row[x][1];
            p2[-x] = row[x][2];
        }
    }
};

// Sum over three planes of |value_c - plane_c[j + i]| for the lanes i = 0..kVec8-1, in two halves.
inline void absSums(const std::vector<std::uint8_t>* planes, const cv::v_uint8* value, std::size_t j,
                    cv::v_uint16& lo, cv::v_uint16& hi) {
    cv::v_uint16 lo0, hi0, lo1, hi1, lo2, hi2;
    cv::v_expand(cv::v_absdiff(value[0], cv::vx_load(planes[0].data() + j)), lo0, hi0);
    cv::v_expand(cv::v_absdiff(value[1], cv::vx_load(planes[1].data() + j)), lo1, hi1);
    cv::v_expand(cv::v_absdiff(value[2], cv::vx_load(planes[2].data() + j)), lo2, hi2);
    lo = lo0 + lo1 + lo2;
    hi = hi0 + hi1 + hi2;
}

// A robust table that stops growing at index `last` (from there on it repeats table[last]).
int saturationIndex(const std::vector<std::uint16_t>& table) {
    int last = static_cast<int>(table.size()) - 1;
    while (last > 0 && table[static_cast<std::size_t>(last - 1)] == table.back()) --last;
    return last;
}

// Hamming distance of Words code words, written out word by word (the compiler keeps a short loop
// otherwise, and the left words in memory instead of registers).
template <std::size_t... W>
int hamming(const std::uint64_t* l, const std::uint64_t* r, std::index_sequence<W...>) {
    return (std::popcount(l[W] ^ r[W]) + ...);
}

// The scalar part of the kernel, one left pixel: Census distance, its term and the colour term(s)
// per disparity. The left code's Words words stay in registers; right pixel x - d is right - d *
// step. On entry cell[d] holds the colour term's index (the vector part writes it there, which
// spares the loop a pointer): colour[cell[d]] is the colour term, with the gradient term folded in
// or added from gradient[gradientIndex[d]] when Gradient.
template <int Words, bool Gradient>
void censusAndLookups(const std::uint64_t* left, const std::uint64_t* right, int step, int valid,
                      const std::uint16_t* census, const std::uint16_t* colour, const std::uint16_t* gradient,
                      const std::uint16_t* gradientIndex, std::uint16_t* cell) {
    std::uint64_t l[Words];
    std::copy(left, left + Words, l);
    auto one = [&](int d, const std::uint64_t* r) {
        int c = census[hamming(l, r, std::make_index_sequence<Words>{})] + colour[cell[d]];
        if constexpr (Gradient) c += gradient[gradientIndex[d]];
        cell[d] = static_cast<std::uint16_t>(c);
    };
    // Two disparities per step: the loop's own work is a good part of so short a body.
    int d = 0;
    for (; d + 1 < valid; d += 2, right -= 2 * step) {
        one(d, right);
        one(d + 1, right - step);
    }
    if (d < valid) one(d, right);
}

// The fused cost of one method. census(l, r) gives its Census term from the two pixels' codes;
// colour and gradient terms come from the sums of absolute differences over the three channels.
struct PaperTerms {
    std::vector<std::uint16_t> census7, census9, ad, gradient;
    std::uint16_t invalid;

    explicit PaperTerms(const Parameters& p)
        : census7(robustTable(4 * 48 + 1, 80.0 / 48.0, p.lambdaCensus)),  // 7x7 distances on the 9x9 scale
          census9(robustTable(4 * 80 + 1, 1.0, p.lambdaCensus)),
          ad(robustTable(3 * 255 + 1, 1.0, p.lambdaAd)),                  // C_AD: sum over R, G, B
          gradient(robustTable(3 * 255 + 1, 1.0 / (3.0 * kGradientSteps), p.lambdaGradient)),  // mean over R, G, B
          invalid(kPaperInvalidCost) {
        adLast = saturationIndex(ad);
        gradientLast = saturationIndex(gradient);
        const int rows = adLast + 1, columns = gradientLast + 1;
        fused = rows * columns <= kMaxFusedEntries;
        if (fused) {
            adGradient.resize(static_cast<std::size_t>(rows * columns));
            for (int a = 0; a < rows; ++a)
                for (int g = 0; g < columns; ++g)
                    adGradient[static_cast<std::size_t>(a * columns + g)] = static_cast<std::uint16_t>(
                        ad[static_cast<std::size_t>(a)] + gradient[static_cast<std::size_t>(g)]);
        }
    }

    // The AD and gradient terms summed in one table, adGradient[min(C_AD, adLast) * (gradientLast
    // + 1) + min(C_grad, gradientLast)]: one lookup per pair instead of two. Both terms saturate
    // early (at 111 and 84 with the default λs: 19 KB), so it stays in L1; beyond kMaxFusedEntries
    // (λs so large that it would not) fused is false and the two tables are looked up apart.
    static constexpr int kMaxFusedEntries = 1 << 14;
    std::vector<std::uint16_t> adGradient;
    int adLast = 0, gradientLast = 0;
    bool fused = false;

    static constexpr bool kUsesGradient = true;

    // Where the lookups of the optimised kernel read, from the sums of absolute differences.
    void indices(const cv::v_uint16& adSum, const cv::v_uint16& gradSum, std::uint16_t* index,
                 std::uint16_t* gradientIndex) const {
        if (fused) {
            cv::v_store(index, cv::v_mul_wrap(cv::v_min(adSum, cv::vx_setall_u16(static_cast<std::uint16_t>(adLast))),
                                              cv::vx_setall_u16(static_cast<std::uint16_t>(gradientLast + 1))) +
                                   cv::v_min(gradSum, cv::vx_setall_u16(static_cast<std::uint16_t>(gradientLast))));
        } else {
            cv::v_store(index, adSum);
            cv::v_store(gradientIndex, gradSum);
        }
    }
    void fill(const std::uint64_t* l, const std::uint64_t* r, int step, int valid, bool use7,
              const std::uint16_t* gradientIndex, std::uint16_t* cell) const {
        if (fused) {
            if (use7) {
                censusAndLookups<kCensus7Words, false>(l + kCensus7Offset, r + kCensus7Offset, step, valid,
                                                       census7.data(), adGradient.data(), nullptr, nullptr, cell);
            } else {
                censusAndLookups<kCensus9Words, false>(l + kCensus9Offset, r + kCensus9Offset, step, valid,
                                                       census9.data(), adGradient.data(), nullptr, nullptr, cell);
            }
        } else if (use7) {
            censusAndLookups<kCensus7Words, true>(l + kCensus7Offset, r + kCensus7Offset, step, valid, census7.data(),
                                                  ad.data(), gradient.data(), gradientIndex, cell);
        } else {
            censusAndLookups<kCensus9Words, true>(l + kCensus9Offset, r + kCensus9Offset, step, valid, census9.data(),
                                                  ad.data(), gradient.data(), gradientIndex, cell);
        }
    }

    // The left pixel's window decides which code both sides are compared with.
    static int hamming(const std::uint64_t* l, const std::uint64_t* r, bool use7) {
        int h = 0;
        if (use7) {
            for (int w = kCensus7Offset; w < kCensus7Offset + kCensus7Words; ++w) h += std::popcount(l[w] ^ r[w]);
        } else {
            for (int w = kCensus9Offset; w < kCensus9Offset + kCensus9Words; ++w) h += std::popcount(l[w] ^ r[w]);
        }
        return h;
    }
    std::uint16_t cost(const std::uint64_t* l, const std::uint64_t* r, bool use7, int adSum, int gradSum) const {
        const int h = hamming(l, r, use7);
        return static_cast<std::uint16_t>((use7 ? census7[h] : census9[h]) + ad[adSum] + gradient[gradSum]);
    }
};

struct MeiTerms {
    std::vector<std::uint16_t> census, ad;
    std::uint16_t invalid;

    explicit MeiTerms(const Parameters& p)
        : census(robustTable(65, 1.0, p.meiLambdaCensus)),
          ad(robustTable(3 * 255 + 1, 1.0 / 3.0, p.meiLambdaAd)),  // Mei: mean over R, G, B
          invalid(kAdCensusInvalidCost) {}

    static constexpr bool kUsesGradient = false;

    void indices(const cv::v_uint16& adSum, const cv::v_uint16&, std::uint16_t* index, std::uint16_t*) const {
        cv::v_store(index, adSum);
    }
    void fill(const std::uint64_t* l, const std::uint64_t* r, int step, int valid, bool, const std::uint16_t*,
              std::uint16_t* cell) const {
        censusAndLookups<1, false>(l, r, step, valid, census.data(), ad.data(), nullptr, nullptr, cell);
    }

    std::uint16_t cost(const std::uint64_t* l, const std::uint64_t* r, bool, int adSum, int) const {
        return static_cast<std::uint16_t>(census[std::popcount(*l ^ *r)] + ad[adSum]);
    }
};

int absSum3(const cv::Vec3b& a, const cv::Vec3b& b) {
    return std::abs(a[0] - b[0]) + std::abs(a[1] - b[1]) + std::abs(a[2] - b[2]);
}

template <class Terms>
void costReference(const Terms& terms, const CostInputs& left, const CostInputs& right, CostVolume& out) {
    const int width = left.bgr.cols;
    for (int y = 0; y < left.bgr.rows; ++y)
        for (int x = 0; x < width; ++x) {
            std::uint16_t* cell = out.at(x, y);
            const bool use7 = !left.windowMask.empty() && left.windowMask.at<std::uint8_t>(y, x) != 0;
            for (int d = 0; d < out.stride; ++d) {
                if (d >= out.disparities) {
                    cell[d] = kPadCost;
                } else if (x - d < 0) {
                    cell[d] = terms.invalid;
                } else {
                    const int adSum = absSum3(left.bgr.at<cv::Vec3b>(y, x), right.bgr.at<cv::Vec3b>(y, x - d));
                    const int gradSum = Terms::kUsesGradient ? absSum3(left.gradient.at<cv::Vec3b>(y, x),
                                                                       right.gradient.at<cv::Vec3b>(y, x - d))
                                                             : 0;
                    cell[d] = terms.cost(left.census->at(x, y), right.census->at(x - d, y), use7, adSum, gradSum);
                }
            }
        }
}

// Row y's Census codes: the whole image's, or made now by the inputs' encoder into one row.
class CensusRow {
public:
    CensusRow(const CostInputs& inputs, int width) : inputs_(inputs), width_(width) {}
    const CensusImage& row(int y) {
        if (inputs_.census) return *inputs_.census;
        inputs_.encoder->encodeRowsHere(y, y + 1, row_);
        row_.viewColumns(inputs_.censusFirstColumn, width_);
        return row_;
    }

private:
    const CostInputs& inputs_;
    int width_;
    CensusImage row_;
};

template <class Terms>
void costOptimised(const Terms& terms, const CostInputs& left, const CostInputs& right, CostVolume& out,
                   const CostRowHook& rowDone) {
    CV_Assert((left.census || left.encoder) && (right.census || right.encoder));
    const int width = left.bgr.cols;
    const int disparities = out.disparities;
    const int blocks = (disparities + kVec8 - 1) / kVec8 * kVec8;
    const int step = right.census ? right.census->words : right.encoder->words();
    forEachStripe(left.bgr.rows, [&](int, int begin, int end) {
        ReversedRow reversed;
        std::vector<std::uint16_t> gradientIndex(static_cast<std::size_t>(blocks));
        CensusRow leftCodes(left, width), rightCodes(right, width);
        for (int y = begin; y < end; ++y) {
            const CensusImage& leftCensus = leftCodes.row(y);
            const CensusImage& rightCensus = rightCodes.row(y);
            reversed.fill(right.bgr, right.gradient, y, width);
            const auto* colour = left.bgr.ptr<cv::Vec3b>(y);
            const auto* grad = Terms::kUsesGradient ? left.gradient.ptr<cv::Vec3b>(y) : nullptr;
            const std::uint8_t* mask = left.windowMask.empty() ? nullptr : left.windowMask.ptr<std::uint8_t>(y);
            for (int x = 0; x < width; ++x) {
                const int valid = std::min(disparities, x + 1);  // right pixel x - d inside the image
                const auto j = static_cast<std::size_t>(width - 1 - x);
                // Reads past the row's end land in the zero padding and are never used.
                const cv::v_uint8 c[3] = {cv::vx_setall_u8(colour[x][0]), cv::vx_setall_u8(colour[x][1]),
                                          cv::vx_setall_u8(colour[x][2])};
                cv::v_uint8 g[3];
                if (Terms::kUsesGradient)
                    for (int k = 0; k < 3; ++k) g[k] = cv::vx_setall_u8(grad[x][k]);
                std::uint16_t* cell = out.at(x, y);
                for (int i = 0; i < valid; i += kVec8) {
                    cv::v_uint16 adLo, adHi, gradLo, gradHi;
                    absSums(reversed.planes, c, j + i, adLo, adHi);
                    if (Terms::kUsesGradient) absSums(reversed.planes + 3, g, j + i, gradLo, gradHi);
                    // The cell holds whole 16-bit vectors only: the upper half goes in when needed.
                    terms.indices(adLo, gradLo, cell + i, gradientIndex.data() + i);
                    if (i + kVec8 / 2 < valid)
                        terms.indices(adHi, gradHi, cell + i + kVec8 / 2, gradientIndex.data() + i + kVec8 / 2);
                }
                terms.fill(leftCensus.at(x, y), rightCensus.at(x, y), step, valid, mask && mask[x] != 0,
                           gradientIndex.data(), cell);
                std::fill(cell + valid, cell + disparities, terms.invalid);
                std::fill(cell + disparities, cell + out.stride, kPadCost);
            }
            if (rowDone) rowDone(y);
        }
    });
}

}  // namespace

void paperCost(const CostInputs& left, const CostInputs& right, const Parameters& parameters, CostVolume& out,
               const CostRowHook& rowDone) {
    costOptimised(PaperTerms(parameters), left, right, out, rowDone);
}

void paperCostReference(const CostInputs& left, const CostInputs& right, const Parameters& parameters,
                        CostVolume& out) {
    costReference(PaperTerms(parameters), left, right, out);
}

void adCensusCost(const CostInputs& left, const CostInputs& right, const Parameters& parameters, CostVolume& out,
                  const CostRowHook& rowDone) {
    costOptimised(MeiTerms(parameters), left, right, out, rowDone);
}

void adCensusCostReference(const CostInputs& left, const CostInputs& right, const Parameters& parameters,
                           CostVolume& out) {
    costReference(MeiTerms(parameters), left, right, out);
}

namespace {

// Transposes 8x8 16-bit values, row i in r[i], in place: interleaving pairs of 16-bit, then
// 32-bit, then 64-bit lanes.
[[gnu::always_inline]] inline void transpose8x8(cv::v_uint16x8 r[8]) {
    cv::v_uint16x8 t[8];
    for (int i = 0; i < 8; i += 2) cv::v_zip(r[i], r[i + 1], t[i], t[i + 1]);
    cv::v_uint32x4 u[8];
    for (int i = 0; i < 8; i += 4) {
        cv::v_zip(cv::v_reinterpret_as_u32(t[i]), cv::v_reinterpret_as_u32(t[i + 2]), u[i], u[i + 1]);
        cv::v_zip(cv::v_reinterpret_as_u32(t[i + 1]), cv::v_reinterpret_as_u32(t[i + 3]), u[i + 2], u[i + 3]);
    }
    for (int i = 0; i < 4; ++i) {
        r[2 * i] = cv::v_reinterpret_as_u16(cv::v_combine_low(u[i], u[i + 4]));
        r[2 * i + 1] = cv::v_reinterpret_as_u16(cv::v_combine_high(u[i], u[i + 4]));
    }
}

}  // namespace

// Read straight off the left volume, the right view's cell is a gather with a stride of one pixel
// plus one disparity, one value at a time. Turned disparity-major (one line per disparity), the
// row's diagonals become plain shifted lines: the row goes there and back by 8x8 vector
// transposes, the way back reading each disparity's line shifted by that disparity.
void rightViewCostsRow(const CostVolume& left, std::uint16_t invalid, CostVolume& mirroredRight, int y) {
    constexpr int kBlock = 8;
    const int width = left.width, disparities = left.disparities, stride = left.stride;
    static_assert(kDisparityAlign % kBlock == 0, "whole blocks along the padded disparity axis");
    // Line d holds cost(x, y, d) for x < width, then what a right pixel whose partner would lie
    // beyond the row's end gets: `invalid`, or kPadCost on the padded disparities.
    const auto pitch = static_cast<std::size_t>((width + stride + kBlock - 1) / kBlock * kBlock);
    thread_local std::vector<std::uint16_t> lines;  // grown once for the largest image
    lines.resize(static_cast<std::size_t>(stride) * pitch);
    // Plain pointers and sizes in locals: read through the volumes' members, they were reloaded
    // after every store.
    std::uint16_t* const linesData = lines.data();
    auto line = [linesData, pitch](int d) { return linesData + static_cast<std::size_t>(d) * pitch; };
    const auto cell = static_cast<std::size_t>(stride);
    const std::uint16_t* const source = left.at(0, y);
    std::uint16_t* const target = mirroredRight.at(0, y);
    const int blockEnd = width / kBlock * kBlock;
    cv::v_uint16x8 r[kBlock];
    for (int x0 = 0; x0 < blockEnd; x0 += kBlock)
        for (int d0 = 0; d0 < disparities; d0 += kBlock) {
            for (int i = 0; i < kBlock; ++i) r[i] = cv::v_load(source + static_cast<std::size_t>(x0 + i) * cell + d0);
            transpose8x8(r);
            for (int j = 0; j < kBlock; ++j) cv::v_store(line(d0 + j) + x0, r[j]);
        }
    for (int x = blockEnd; x < width; ++x)
        for (int d = 0; d < disparities; ++d) line(d)[x] = left.at(x, y)[d];
    for (int d = 0; d < stride; ++d) {
        std::uint16_t* l = line(d);
        if (d < disparities) {
            std::fill(l + width, l + pitch, invalid);
        } else {
            std::fill(l, l + pitch, kPadCost);
        }
    }
    // Right pixel x at d is left pixel x + d: line d from x + d on; stored at column width - 1 - x.
    for (int x0 = 0; x0 < blockEnd; x0 += kBlock)
        for (int d0 = 0; d0 < stride; d0 += kBlock) {
            for (int j = 0; j < kBlock; ++j) r[j] = cv::v_load(line(d0 + j) + x0 + d0 + j);
            transpose8x8(r);
            for (int i = 0; i < kBlock; ++i) {
                cv::v_store(target + static_cast<std::size_t>(width - 1 - (x0 + i)) * cell + d0, r[i]);
            }
        }
    for (int x = blockEnd; x < width; ++x) {
        std::uint16_t* out = target + static_cast<std::size_t>(width - 1 - x) * cell;
        for (int d = 0; d < stride; ++d) out[d] = line(d)[x + d];
    }
}

void rightViewCosts(const CostVolume& left, std::uint16_t invalid, CostVolume& mirroredRight) {
    mirroredRight.create(left.width, left.height, left.disparities);
    forEachStripe(left.height, [&](int, int begin, int end) {
        for (int y = begin; y < end; ++y) rightViewCostsRow(left, invalid, mirroredRight, y);
    });
}

}  // namespace icewatch::stereo::detail
