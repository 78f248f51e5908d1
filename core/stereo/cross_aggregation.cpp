// Cross-based cost aggregation (Zhang et al. 2009, with Mei et al.'s enhanced arm rules, as the
// seed paper uses them).
//
// Every pixel grows four arms while the colour stays close to its own: D_c(p1, p) < τ1 and
// D_c(p1, p1 + step back) < τ1 (no arm runs through a thin edge), D_s(p1, p) < L1, and beyond L2
// the tighter D_c(p1, p) < τ2 (long arms only in really flat areas). The support region of p is
// the union of the horizontal arms of the pixels on its vertical arm; aggregation sums costs over
// the horizontal arms first, then sums those along the vertical arm, and divides by the region's
// pixel count. As in Mei et al. 2011, iterations alternate the order: odd ones go vertical first
// (the region is then the union of the vertical arms of the pixels on the horizontal arm), so
// repeated passes do not favour one axis. The first pass keeps each pixel's mean and count, so the
// second can weight means by counts and divide by the whole region exactly.
//
// Horizontal sums come from a per-row prefix sum, vertical sums from a per-column one (32-bit);
// both take the padded disparity axis one vector of lanes at a time, so the prefix sums of a line
// stay in the nearest cache.
#include <algorithm>
#include <cstdlib>
#include <utility>

#include "core/common/simd.hpp"

#include "core/stereo/stages.hpp"

namespace icewatch::stereo::detail {

int colourDistance(const cv::Vec3b& a, const cv::Vec3b& b) {
    return std::max({std::abs(a[0] - b[0]), std::abs(a[1] - b[1]), std::abs(a[2] - b[2])});
}

namespace {

// Length of the arm from (x, y) in direction (dx, dy): the plain definition.
int armLength(const cv::Mat& bgr, int x, int y, int dx, int dy, const Parameters& p) {
    const cv::Vec3b& centre = bgr.at<cv::Vec3b>(y, x);
    int length = 0;
    for (int k = 1; k < p.crossL1; ++k) {
        const int qx = x + k * dx, qy = y + k * dy;
        if (qx < 0 || qy < 0 || qx >= bgr.cols || qy >= bgr.rows) break;
        const cv::Vec3b& q = bgr.at<cv::Vec3b>(qy, qx);
        const int toCentre = colourDistance(q, centre);
        if (toCentre >= p.crossTau1) break;
        if (colourDistance(q, bgr.at<cv::Vec3b>(qy - dy, qx - dx)) >= p.crossTau1) break;
        if (k > p.crossL2 && toCentre >= p.crossTau2) break;
        length = k;
    }
    return length;
}

inline int maxAbsDiff3(const std::uint8_t* a, const std::uint8_t* b) {
    const int d0 = std::abs(a[0] - b[0]), d1 = std::abs(a[1] - b[1]), d2 = std::abs(a[2] - b[2]);
    return std::max(d0, std::max(d1, d2));
}

// The same with raw pointers: `step` bytes between neighbours along the arm, `room` pixels until
// the image border.
int armLengthFast(const std::uint8_t* centre, std::ptrdiff_t step, int room, const Parameters& p) {
    const int limit = std::min(p.crossL1 - 1, room);
    const std::uint8_t* previous = centre;
    for (int k = 1; k <= limit; ++k) {
        const std::uint8_t* q = previous + step;
        const int toCentre = maxAbsDiff3(q, centre);
        if (toCentre >= p.crossTau1 || maxAbsDiff3(q, previous) >= p.crossTau1 ||
            (k > p.crossL2 && toCentre >= p.crossTau2)) {
            return k - 1;
        }
        previous = q;
    }
    return limit;
}

std::uint16_t roundedMean(std::uint32_t sum, float inverseCount) {
    return static_cast<std::uint16_t>(cvRound(static_cast<float>(static_cast<std::int32_t>(sum)) * inverseCount));
}

constexpr int kLanes = cv::v_uint16::nlanes;
constexpr int kLanes32 = cv::v_uint32::nlanes;
static_assert(kDisparityAlign % kLanes == 0, "whole vectors along the padded disparity axis");

// Rounded means of one vector of 16-bit lanes, given as its two halves of 32-bit sums.
cv::v_uint16 meanLanes(const cv::v_uint32& lo, const cv::v_uint32& hi, const cv::v_float32& inverse) {
    const cv::v_int32 a = cv::v_round(cv::v_cvt_f32(cv::v_reinterpret_as_s32(lo)) * inverse);
    const cv::v_int32 b = cv::v_round(cv::v_cvt_f32(cv::v_reinterpret_as_s32(hi)) * inverse);
    return cv::v_pack_u(a, b);
}

void restorePadding(CostVolume& volume) {
    if (volume.stride == volume.disparities) return;
    forEachStripe(volume.height, [&](int, int begin, int end) {
        for (int y = begin; y < end; ++y)
            for (int x = 0; x < volume.width; ++x) {
                std::fill(volume.at(x, y) + volume.disparities, volume.at(x, y) + volume.stride, kPadCost);
            }
    });
}

}  // namespace

namespace {

constexpr int kLanes8 = cv::v_uint8::nlanes;  // the widest vector: 32 with AVX2, 16 with SSE or NEON
// Columns of border around the colour planes: arms are at most 126 long (the config caps crossL1
// at 127), so whole-vector loads along a row never leave the planes.
constexpr int kPlaneBorder = 128;

// Largest channel difference of a vector of pixels, one vector per colour plane.
cv::v_uint8 maxAbsDiff3(const cv::v_uint8 a[3], const cv::v_uint8 b[3]) {
    return cv::v_max(cv::v_absdiff(a[0], b[0]), cv::v_max(cv::v_absdiff(a[1], b[1]), cv::v_absdiff(a[2], b[2])));
}

// Arm lengths of a vector of neighbouring pixels of one row at once, in one direction: `step` elements
// between neighbours along the arm (a row of the planes or 1), `room` per lane the pixels until
// the image border (saturated at 255). A lane stops growing at its first failed rule; the loop
// stops when every lane has.
cv::v_uint8 armLengths(const std::uint8_t* const centre[3], std::ptrdiff_t step, const cv::v_uint8& room, int maxRoom,
                       const Parameters& p) {
    cv::v_uint8 c[3], previous[3];
    for (int ch = 0; ch < 3; ++ch) c[ch] = previous[ch] = cv::vx_load(centre[ch]);
    const cv::v_uint8 tau1 = cv::vx_setall_u8(static_cast<std::uint8_t>(p.crossTau1));
    const cv::v_uint8 tau2 = cv::vx_setall_u8(static_cast<std::uint8_t>(p.crossTau2));
    cv::v_uint8 alive = cv::vx_setall_u8(0xFF), length = cv::vx_setzero_u8();
    const int limit = std::min(p.crossL1 - 1, maxRoom);
    for (int k = 1; k <= limit; ++k) {
        cv::v_uint8 q[3];
        for (int ch = 0; ch < 3; ++ch) q[ch] = cv::vx_load(centre[ch] + k * step);
        const cv::v_uint8 toCentre = maxAbsDiff3(q, c);
        cv::v_uint8 ok = (toCentre < tau1) & (maxAbsDiff3(q, previous) < tau1) &
                         (cv::vx_setall_u8(static_cast<std::uint8_t>(k)) <= room);
        if (k > p.crossL2) ok &= toCentre < tau2;
        alive &= ok;
        if (!cv::v_check_any(alive)) break;
        length += alive & cv::vx_setall_u8(1);  // one more pixel where still alive
        for (int ch = 0; ch < 3; ++ch) previous[ch] = q[ch];
    }
    return length;
}

}  // namespace

void computeCrossArms(const cv::Mat& bgr, const Parameters& parameters, CrossArms& arms) {
    CV_Assert(bgr.type() == CV_8UC3);
    CV_Assert(parameters.crossL1 <= kPlaneBorder - 1);
    for (cv::Mat* m : {&arms.left, &arms.right, &arms.up, &arms.down}) m->create(bgr.size(), CV_8UC1);
    // Planar colour with a border: the vector kernel compares a vector of pixels per channel at a time.
    cv::Mat split[3];
    cv::split(bgr, split);
    for (int ch = 0; ch < 3; ++ch) {
        cv::copyMakeBorder(split[ch], arms.planes[ch], 0, 0, kPlaneBorder, kPlaneBorder, cv::BORDER_CONSTANT, 0);
    }
    const int width = bgr.cols, height = bgr.rows, vectorEnd = width / kLanes8 * kLanes8;
    const auto rowStep = static_cast<std::ptrdiff_t>(arms.planes[0].step[0]);
    const auto bgrRowStep = static_cast<std::ptrdiff_t>(bgr.step[0]);
    forEachStripe(height, [&](int, int begin, int end) {
        std::uint8_t roomLeft[kLanes8], roomRight[kLanes8];
        for (int y = begin; y < end; ++y) {
            for (int x = 0; x < vectorEnd; x += kLanes8) {
                const std::uint8_t* centre[3];
                for (int ch = 0; ch < 3; ++ch) centre[ch] = arms.planes[ch].ptr<std::uint8_t>(y) + kPlaneBorder + x;
                for (int i = 0; i < kLanes8; ++i) {
                    roomLeft[i] = static_cast<std::uint8_t>(std::min(x + i, 255));
                    roomRight[i] = static_cast<std::uint8_t>(std::min(width - 1 - x - i, 255));
                }
                const cv::v_uint8 all = cv::vx_setall_u8(255);
                cv::v_store(arms.left.ptr<std::uint8_t>(y) + x,
                            armLengths(centre, -1, cv::vx_load(roomLeft), x + kLanes8 - 1, parameters));
                cv::v_store(arms.right.ptr<std::uint8_t>(y) + x,
                            armLengths(centre, 1, cv::vx_load(roomRight), width - 1 - x, parameters));
                cv::v_store(arms.up.ptr<std::uint8_t>(y) + x, armLengths(centre, -rowStep, all, y, parameters));
                cv::v_store(arms.down.ptr<std::uint8_t>(y) + x,
                            armLengths(centre, rowStep, all, height - 1 - y, parameters));
            }
            // The last columns, fewer than a vector: one pixel at a time.
            const std::uint8_t* row = bgr.ptr<std::uint8_t>(y);
            for (int x = vectorEnd; x < width; ++x) {
                const std::uint8_t* centre = row + 3 * x;
                arms.left.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>(armLengthFast(centre, -3, x, parameters));
                arms.right.at<std::uint8_t>(y, x) =
                    static_cast<std::uint8_t>(armLengthFast(centre, 3, width - 1 - x, parameters));
                arms.up.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>(armLengthFast(centre, -bgrRowStep, y, parameters));
                arms.down.at<std::uint8_t>(y, x) =
                    static_cast<std::uint8_t>(armLengthFast(centre, bgrRowStep, height - 1 - y, parameters));
            }
        }
    });
}

void computeCrossArmsReference(const cv::Mat& bgr, const Parameters& parameters, CrossArms& arms) {
    for (cv::Mat* m : {&arms.left, &arms.right, &arms.up, &arms.down}) m->create(bgr.size(), CV_8UC1);
    for (int y = 0; y < bgr.rows; ++y)
        for (int x = 0; x < bgr.cols; ++x) {
            arms.left.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>(armLength(bgr, x, y, -1, 0, parameters));
            arms.right.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>(armLength(bgr, x, y, 1, 0, parameters));
            arms.up.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>(armLength(bgr, x, y, 0, -1, parameters));
            arms.down.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>(armLength(bgr, x, y, 0, 1, parameters));
        }
}

namespace {

// The two pass orders. Horizontal-first: region = the horizontal arms of the pixels on p's
// vertical arm; vertical-first: the vertical arms of the pixels on p's horizontal arm.
bool horizontalFirst(int iteration) { return iteration % 2 == 0; }

// Where each pixel's window lies in the prefix sums of its line and how its sum becomes a mean:
// prefix entries `from` and `to` (both pre-multiplied by the entry's size) and 1 / pixel count.
struct Windows {
    std::vector<std::int32_t> from, to;
    std::vector<float> inverse;
    std::vector<std::uint16_t> weight;        // per pixel (weighted passes)
    std::vector<std::uint32_t> weightPrefix;  // per line, scratch

    void resize(std::size_t pixels) {
        from.resize(pixels);
        to.resize(pixels);
        inverse.resize(pixels);
        weight.resize(pixels);
        weightPrefix.resize(pixels + 1);
    }
};

// Windows of `lines` neighbouring lines of n pixels each, pixel i of line k at index i * lines + k:
// arms a (towards 0) and b (towards n) at a[i * armStep + k], b likewise; kWeighted: the pixel
// weights are in windows.weight, else 1.
template <bool kWeighted>
void setWindows(const std::uint8_t* a, const std::uint8_t* b, std::ptrdiff_t armStep, int n, int lines,
                Windows& windows) {
    for (int k = 0; k < lines; ++k) {
        if (kWeighted) {
            windows.weightPrefix[0] = 0;
            for (int i = 0; i < n; ++i) {
                const auto at = static_cast<std::size_t>(i);
                windows.weightPrefix[at + 1] =
                    windows.weightPrefix[at] + windows.weight[static_cast<std::size_t>(i * lines + k)];
            }
        }
        for (int i = 0; i < n; ++i) {
            const int i0 = i - a[i * armStep + k], i1 = i + b[i * armStep + k] + 1;
            const auto count = kWeighted ? windows.weightPrefix[static_cast<std::size_t>(i1)] -
                                               windows.weightPrefix[static_cast<std::size_t>(i0)]
                                         : static_cast<std::uint32_t>(i1 - i0);
            const auto j = static_cast<std::size_t>(i * lines + k);
            windows.from[j] = (i0 * lines + k) * 2 * kLanes32;
            windows.to[j] = (i1 * lines + k) * 2 * kLanes32;
            windows.inverse[j] = 1.0f / static_cast<float>(count);
        }
    }
}

// Means over the windows of kLines neighbouring lines of n pixels: pixel i of line k has its
// costs at cost + i * pixelStep + k * lineStep and its mean goes to the same place in out (which
// may be cost: a vector of lanes is written only after the whole line of it is summed). The
// disparity axis goes one vector at a time, so the prefix sums of the lines (32-bit, wrapping:
// differences of wrapped sums stay exact as every window sum fits) take (n + 1) * kLines * 64 bytes
// with AVX2 and stay in the nearest cache.
template <bool kWeighted, int kLines>
void lineMeans(const std::uint16_t* cost, std::uint16_t* out, std::ptrdiff_t pixelStep, std::ptrdiff_t lineStep,
               int n, int stride, const Windows& windows, AlignedVector<std::uint32_t>& prefix) {
    constexpr int kEntry = 2 * kLanes32;  // one vector of 16-bit lanes as 32-bit sums
    // With AVX2 an entry is 64 bytes, each on its own cache line (AlignedVector).
    prefix.resize(static_cast<std::size_t>(n + 1) * kLines * kEntry);
    std::uint32_t* const sums = prefix.data();
    const std::int32_t* const from = windows.from.data();
    const std::int32_t* const to = windows.to.data();
    const float* const inverse = windows.inverse.data();
    const std::uint16_t* const weight = windows.weight.data();
    for (int d = 0; d < stride; d += kLanes) {
        cv::v_uint32 lo[kLines], hi[kLines];
        for (int k = 0; k < kLines; ++k) {
            lo[k] = hi[k] = cv::vx_setzero_u32();
            cv::v_store(sums + k * kEntry, lo[k]);
            cv::v_store(sums + k * kEntry + kLanes32, hi[k]);
        }
        std::uint32_t* after = sums + kLines * kEntry;
        for (int i = 0; i < n; ++i) {
            const std::uint16_t* c = cost + i * pixelStep + d;
            // Down a block of columns: the cells a few rows ahead, read now and written in place
            // below (prefetchCells).
            if (kLines > 1 && d == 0 && i + kPrefetchRows < n) {
                prefetchCells(c + kPrefetchRows * pixelStep, kLines * stride, true);
            }
            for (int k = 0; k < kLines; ++k, after += kEntry) {
                cv::v_uint32 a, b;
                if constexpr (kWeighted) {
                    cv::v_mul_expand(cv::vx_load(c + k * lineStep), cv::vx_setall_u16(weight[i * kLines + k]), a, b);
                } else {
                    cv::v_expand(cv::vx_load(c + k * lineStep), a, b);
                }
                lo[k] += a;
                hi[k] += b;
                cv::v_store(after, lo[k]);
                cv::v_store(after + kLanes32, hi[k]);
            }
        }
        for (int i = 0; i < n; ++i) {
            std::uint16_t* o = out + i * pixelStep + d;
            for (int k = 0; k < kLines; ++k) {
                const int j = i * kLines + k;
                const std::uint32_t* begin = sums + from[j];
                const std::uint32_t* end = sums + to[j];
                const cv::v_uint32 a = cv::vx_load(end) - cv::vx_load(begin);
                const cv::v_uint32 b = cv::vx_load(end + kLanes32) - cv::vx_load(begin + kLanes32);
                cv::v_store(o + k * lineStep, meanLanes(a, b, cv::vx_setall_f32(inverse[j])));
            }
        }
    }
}

// Weighted mean along each pixel's horizontal arm in row y, in place: out(p) = Σ w(q) c(q) / Σ w(q),
// q on the arm; kWeighted: w(q) is q's vertical line count, else 1.
template <bool kWeighted>
void rowMeans(const CrossArms& arms, CostVolume& costs, int y) {
    const int width = costs.width, stride = costs.stride;
    // Per thread, grown once for the largest image (no allocation per pair).
    thread_local Windows windows;
    thread_local AlignedVector<std::uint32_t> prefix;
    windows.resize(static_cast<std::size_t>(width));
    if (kWeighted) {
        const std::uint8_t* up = arms.up.ptr<std::uint8_t>(y);
        const std::uint8_t* down = arms.down.ptr<std::uint8_t>(y);
        for (int x = 0; x < width; ++x) {
            windows.weight[static_cast<std::size_t>(x)] = static_cast<std::uint16_t>(up[x] + down[x] + 1);
        }
    }
    setWindows<kWeighted>(arms.left.ptr<std::uint8_t>(y), arms.right.ptr<std::uint8_t>(y), 1, width, 1, windows);
    std::uint16_t* row = costs.at(0, y);
    lineMeans<kWeighted, 1>(row, row, stride, 0, width, stride, windows, prefix);
}

// The same for every row, rows split over stripes.
template <bool kWeighted>
void horizontalMeans(const CrossArms& arms, CostVolume& costs) {
    forEachStripe(costs.height, [&](int, int begin, int end) {
        for (int y = begin; y < end; ++y) rowMeans<kWeighted>(arms, costs, y);
    });
}

// Weighted mean along each pixel's vertical arm, in place; kWeighted: w(q) is q's horizontal line
// count, else 1. Columns split over stripes. A block of neighbouring columns is summed together:
// walking one column alone would jump a whole image row in memory for every vector it reads. In
// place, the block's costs are still in the nearest caches when their means are written over
// them; written to another volume, every line of that volume had to be fetched from memory first.
// The block is read once per disparity vector, so it should stay in the core's own cache between
// those reads: four columns (a 1280x720 frame at 128 disparities: 0.7 MiB) measured faster than
// eight on both Cones at 64 disparities (vertical pass 3.7-3.9 to 3.1-3.3 ms per view) and 1280x720
// at 128 (66-71 to 54-58 ms).
constexpr int kColumnBlock = 4;

// The kLines columns from x0 on.
template <bool kWeighted, int kLines>
void columnMeans(const CrossArms& arms, CostVolume& costs, int x0, Windows& windows,
                 AlignedVector<std::uint32_t>& prefix) {
    const int height = costs.height;
    if (kWeighted) {
        for (int y = 0; y < height; ++y) {
            const std::uint8_t* left = arms.left.ptr<std::uint8_t>(y) + x0;
            const std::uint8_t* right = arms.right.ptr<std::uint8_t>(y) + x0;
            for (int k = 0; k < kLines; ++k) {
                windows.weight[static_cast<std::size_t>(y * kLines + k)] =
                    static_cast<std::uint16_t>(left[k] + right[k] + 1);
            }
        }
    }
    const auto armStep = static_cast<std::ptrdiff_t>(arms.up.step[0]);
    setWindows<kWeighted>(arms.up.ptr<std::uint8_t>() + x0, arms.down.ptr<std::uint8_t>() + x0, armStep, height,
                          kLines, windows);
    const auto rowStep = static_cast<std::ptrdiff_t>(costs.width) * costs.stride;
    lineMeans<kWeighted, kLines>(costs.at(x0, 0), costs.at(x0, 0), rowStep, costs.stride, height, costs.stride,
                                 windows, prefix);
}

template <bool kWeighted>
void verticalMeans(const CrossArms& arms, CostVolume& costs) {
    forEachStripe(costs.width, [&](int, int begin, int end) {
        thread_local Windows windows;
        thread_local AlignedVector<std::uint32_t> prefix;
        windows.resize(static_cast<std::size_t>(costs.height) * kColumnBlock);
        int x = begin;
        for (; end - x >= kColumnBlock; x += kColumnBlock) {
            columnMeans<kWeighted, kColumnBlock>(arms, costs, x, windows, prefix);
        }
        // The rest: a half block, then single columns (blocks must not overlap: the pass is in place).
        constexpr int kHalfBlock = kColumnBlock / 2;
        if (end - x >= kHalfBlock) {
            columnMeans<kWeighted, kHalfBlock>(arms, costs, x, windows, prefix);
            x += kHalfBlock;
        }
        for (; x < end; ++x) columnMeans<kWeighted, 1>(arms, costs, x, windows, prefix);
    });
}

}  // namespace

void meanAlongRow(const CrossArms& arms, CostVolume& costs, int y) {
    rowMeans<false>(arms, costs, y);
}

void aggregateCross(const CrossArms& arms, int iterations, CostVolume& costs, bool rowsDone) {
    for (int iteration = 0; iteration < iterations; ++iteration) {
        if (horizontalFirst(iteration)) {
            if (iteration > 0 || !rowsDone) horizontalMeans<false>(arms, costs);
            verticalMeans<true>(arms, costs);
        } else {
            verticalMeans<false>(arms, costs);
            horizontalMeans<true>(arms, costs);
        }
    }
    restorePadding(costs);
}

void aggregateCrossReference(const CrossArms& arms, int iterations, CostVolume& costs) {
    const int width = costs.width, height = costs.height;
    CostVolume first;
    first.create(width, height, costs.disparities);
    // Arm extent of (x, y) along one axis: [x - a, x + b] or [y - a, y + b].
    auto horizontalArm = [&](int x, int y) {
        return std::pair<int, int>(x - arms.left.at<std::uint8_t>(y, x), x + arms.right.at<std::uint8_t>(y, x));
    };
    auto verticalArm = [&](int x, int y) {
        return std::pair<int, int>(y - arms.up.at<std::uint8_t>(y, x), y + arms.down.at<std::uint8_t>(y, x));
    };
    for (int iteration = 0; iteration < iterations; ++iteration) {
        const bool hFirst = horizontalFirst(iteration);
        // First pass: plain mean along the first axis' arm.
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x) {
                const auto [a, b] = hFirst ? horizontalArm(x, y) : verticalArm(x, y);
                const float inverse = 1.0f / static_cast<float>(b - a + 1);
                for (int d = 0; d < costs.stride; ++d) {
                    std::uint32_t sum = 0;
                    for (int t = a; t <= b; ++t) sum += hFirst ? costs.at(t, y)[d] : costs.at(x, t)[d];
                    first.at(x, y)[d] = roundedMean(sum, inverse);
                }
            }
        // Second pass along the other axis: each first-pass mean weighted by its pixel count.
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x) {
                const auto [a, b] = hFirst ? verticalArm(x, y) : horizontalArm(x, y);
                auto weight = [&](int t) {
                    const auto [c0, c1] = hFirst ? horizontalArm(x, t) : verticalArm(t, y);
                    return static_cast<std::uint32_t>(c1 - c0 + 1);
                };
                std::uint32_t count = 0;
                for (int t = a; t <= b; ++t) count += weight(t);
                const float inverse = 1.0f / static_cast<float>(count);
                for (int d = 0; d < costs.stride; ++d) {
                    std::uint32_t sum = 0;
                    for (int t = a; t <= b; ++t) sum += weight(t) * (hFirst ? first.at(x, t)[d] : first.at(t, y)[d]);
                    costs.at(x, y)[d] = roundedMean(sum, inverse);
                }
            }
    }
    restorePadding(costs);
}

}  // namespace icewatch::stereo::detail
