// Per-pixel matching costs, fused into one 16-bit fixed-point volume.
//
// Every term is robustified as 1 - exp(-C / λ) (the seed paper's fusion, after Mei et al.), so no
// single feature dominates and the sum stays in [0, terms). The exponentials are lookup tables
// indexed by the integer raw cost, built once per compute().
//
// The optimised kernel reverses the right row so that the right pixels x - d, d = 0, 1, ... are
// contiguous: the absolute differences of colour and gradient then run a vector of disparities at
// a time (OpenCV universal intrinsics: 32 with AVX2, 16 with SSE or NEON); the table lookups and
// the Census popcounts stay scalar.
#include <algorithm>
#include <bit>
#include <cmath>
#include <type_traits>

#include "core/common/simd.hpp"

#include "core/stereo/stages.hpp"

namespace icewatch::stereo::detail {

void CostVolume::create(int w, int h, int d) {
    width = w;
    height = h;
    disparities = d;
    stride = paddedDisparities(d);
    data.resize(static_cast<std::size_t>(w) * h * stride);
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
          invalid(kPaperInvalidCost) {}

    static constexpr bool kUsesGradient = true;

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

constexpr int kVec8 = cv::v_uint8::nlanes;  // the widest vector: 32 with AVX2, 16 with SSE or NEON

// Planar copies of a row, reversed, with kVec8 zero bytes after the end for whole-vector loads.
struct ReversedRow {
    std::vector<std::uint8_t> planes[6];

    void fill(const cv::Mat& bgr, const cv::Mat& gradient, int y, int width) {
        for (int c = 0; c < 6; ++c) planes[c].assign(static_cast<std::size_t>(width + kVec8), 0);
        const auto* colour = bgr.ptr<cv::Vec3b>(y);
        const auto* grad = gradient.empty() ? nullptr : gradient.ptr<cv::Vec3b>(y);
        for (int x = 0; x < width; ++x) {
            const auto j = static_cast<std::size_t>(width - 1 - x);
            for (int c = 0; c < 3; ++c) {
                planes[c][j] = colour[x][c];
                if (grad) planes[3 + c][j] = grad[x][c];
            }
        }
    }
};

// Sum over three planes of |value_c - plane_c[j + i]|, i = 0..count-1, vectorised.
void absSums(const std::vector<std::uint8_t>* planes, const std::uint8_t* value, std::size_t j, int count,
             std::uint16_t* out) {
    const cv::v_uint8 v0 = cv::vx_setall_u8(value[0]);
    const cv::v_uint8 v1 = cv::vx_setall_u8(value[1]);
    const cv::v_uint8 v2 = cv::vx_setall_u8(value[2]);
    for (int i = 0; i < count; i += kVec8) {
        cv::v_uint16 lo0, hi0, lo1, hi1, lo2, hi2;
        cv::v_expand(cv::v_absdiff(v0, cv::vx_load(planes[0].data() + j + i)), lo0, hi0);
        cv::v_expand(cv::v_absdiff(v1, cv::vx_load(planes[1].data() + j + i)), lo1, hi1);
        cv::v_expand(cv::v_absdiff(v2, cv::vx_load(planes[2].data() + j + i)), lo2, hi2);
        cv::v_store(out + i, lo0 + lo1 + lo2);
        cv::v_store(out + i + kVec8 / 2, hi0 + hi1 + hi2);
    }
}

template <class Terms>
void costOptimised(const Terms& terms, const CostInputs& left, const CostInputs& right, CostVolume& out) {
    const int width = left.bgr.cols;
    const int disparities = out.disparities;
    const int blocks = (disparities + kVec8 - 1) / kVec8 * kVec8;
    forEachStripe(left.bgr.rows, [&](int, int begin, int end) {
        ReversedRow reversed;
        std::vector<std::uint16_t> adSums(static_cast<std::size_t>(blocks)), gradSums(static_cast<std::size_t>(blocks));
        for (int y = begin; y < end; ++y) {
            reversed.fill(right.bgr, right.gradient, y, width);
            const auto* colour = left.bgr.ptr<cv::Vec3b>(y);
            const auto* grad = Terms::kUsesGradient ? left.gradient.ptr<cv::Vec3b>(y) : nullptr;
            const std::uint8_t* mask = left.windowMask.empty() ? nullptr : left.windowMask.ptr<std::uint8_t>(y);
            for (int x = 0; x < width; ++x) {
                const int valid = std::min(disparities, x + 1);  // right pixel x - d inside the image
                const auto j = static_cast<std::size_t>(width - 1 - x);
                // Reads past the row's end land in the zero padding and are never used.
                absSums(reversed.planes, &colour[x][0], j, valid, adSums.data());
                if (Terms::kUsesGradient) absSums(reversed.planes + 3, &grad[x][0], j, valid, gradSums.data());
                const std::uint64_t* l = left.census->at(x, y);
                const std::uint64_t* r = right.census->at(x, y);
                const bool use7 = mask && mask[x] != 0;
                const int words = right.census->words;
                std::uint16_t* cell = out.at(x, y);
                // The window choice is fixed per pixel: one loop each, no branch per disparity.
                auto fill = [&](auto window) {
                    for (int d = 0; d < valid; ++d) {
                        cell[d] = terms.cost(l, r - d * words, decltype(window)::value, adSums[static_cast<std::size_t>(d)],
                                             Terms::kUsesGradient ? gradSums[static_cast<std::size_t>(d)] : 0);
                    }
                };
                if (use7) {
                    fill(std::true_type{});
                } else {
                    fill(std::false_type{});
                }
                std::fill(cell + valid, cell + disparities, terms.invalid);
                std::fill(cell + disparities, cell + out.stride, kPadCost);
            }
        }
    });
}

}  // namespace

void paperCost(const CostInputs& left, const CostInputs& right, const Parameters& parameters, CostVolume& out) {
    costOptimised(PaperTerms(parameters), left, right, out);
}

void paperCostReference(const CostInputs& left, const CostInputs& right, const Parameters& parameters,
                        CostVolume& out) {
    costReference(PaperTerms(parameters), left, right, out);
}

void adCensusCost(const CostInputs& left, const CostInputs& right, const Parameters& parameters, CostVolume& out) {
    costOptimised(MeiTerms(parameters), left, right, out);
}

void adCensusCostReference(const CostInputs& left, const CostInputs& right, const Parameters& parameters,
                           CostVolume& out) {
    costReference(MeiTerms(parameters), left, right, out);
}

void rightViewCosts(const CostVolume& left, std::uint16_t invalid, CostVolume& mirroredRight) {
    const int width = left.width, disparities = left.disparities;
    mirroredRight.create(width, left.height, disparities);
    forEachStripe(left.height, [&](int, int begin, int end) {
        for (int y = begin; y < end; ++y)
            for (int x = 0; x < width; ++x) {
                std::uint16_t* cell = mirroredRight.at(width - 1 - x, y);
                const int valid = std::min(disparities, width - x);  // left pixel x + d inside
                for (int d = 0; d < valid; ++d) cell[d] = left.at(x + d, y)[d];
                std::fill(cell + valid, cell + disparities, invalid);
                std::fill(cell + disparities, cell + mirroredRight.stride, kPadCost);
            }
    });
}

}  // namespace icewatch::stereo::detail
