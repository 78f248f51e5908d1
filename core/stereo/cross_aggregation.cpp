// Cross-based cost aggregation (Zhang et al. 2009, with Mei et al.'s enhanced arm rules, as the
// seed paper uses them).
//
// Every pixel grows four arms while the colour stays close to its own: D_c(p1, p) < τ1 and
// D_c(p1, p1 + step back) < τ1 (no arm runs through a thin edge), D_s(p1, p) < L1, and beyond L2
// the tighter D_c(p1, p) < τ2 (long arms only in really flat areas). The support region of p is
// the union of the horizontal arms of the pixels on its vertical arm; aggregation sums costs over
// the horizontal arms first, then sums those along the vertical arm, and divides by the region's
// pixel count. The horizontal pass keeps each pixel's horizontal mean and count, so the vertical
// pass can weight means by counts and divide by the whole region exactly.
//
// Horizontal sums come from a per-row prefix sum (32-bit), vertical sums add the arm's rows;
// both run over the padded disparity axis 8 lanes at a time.
#include <algorithm>
#include <cstdlib>

#include <opencv2/core/hal/intrin.hpp>

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

constexpr int kLanes = cv::v_uint16x8::nlanes;
constexpr int kLanes32 = cv::v_uint32x4::nlanes;

// Rounded mean of 8 lanes given as two 4-lane sums.
cv::v_uint16x8 meanLanes(const cv::v_uint32x4& lo, const cv::v_uint32x4& hi, const cv::v_float32x4& inverse) {
    const cv::v_int32x4 a = cv::v_round(cv::v_cvt_f32(cv::v_reinterpret_as_s32(lo)) * inverse);
    const cv::v_int32x4 b = cv::v_round(cv::v_cvt_f32(cv::v_reinterpret_as_s32(hi)) * inverse);
    return cv::v_pack_u(a, b);
}

void restorePadding(CostVolume& volume) {
    if (volume.stride == volume.disparities) return;
    for (int y = 0; y < volume.height; ++y)
        for (int x = 0; x < volume.width; ++x) {
            std::fill(volume.at(x, y) + volume.disparities, volume.at(x, y) + volume.stride, kPadCost);
        }
}

}  // namespace

void computeCrossArms(const cv::Mat& bgr, const Parameters& parameters, CrossArms& arms) {
    CV_Assert(bgr.type() == CV_8UC3);
    for (cv::Mat* m : {&arms.left, &arms.right, &arms.up, &arms.down}) m->create(bgr.size(), CV_8UC1);
    const auto rowStep = static_cast<std::ptrdiff_t>(bgr.step[0]);
    forEachStripe(bgr.rows, [&](int, int begin, int end) {
        for (int y = begin; y < end; ++y) {
            const std::uint8_t* row = bgr.ptr<std::uint8_t>(y);
            for (int x = 0; x < bgr.cols; ++x) {
                const std::uint8_t* centre = row + 3 * x;
                arms.left.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>(armLengthFast(centre, -3, x, parameters));
                arms.right.at<std::uint8_t>(y, x) =
                    static_cast<std::uint8_t>(armLengthFast(centre, 3, bgr.cols - 1 - x, parameters));
                arms.up.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>(armLengthFast(centre, -rowStep, y, parameters));
                arms.down.at<std::uint8_t>(y, x) =
                    static_cast<std::uint8_t>(armLengthFast(centre, rowStep, bgr.rows - 1 - y, parameters));
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

void aggregateCross(const CrossArms& arms, int iterations, CostVolume& costs, CostVolume& scratch) {
    const int width = costs.width, height = costs.height, stride = costs.stride;
    scratch.create(width, height, costs.disparities);
    for (int iteration = 0; iteration < iterations; ++iteration) {
        // Horizontal pass, in place: each row's prefix sums are taken before the row is overwritten.
        forEachStripe(height, [&](int, int begin, int end) {
            std::vector<std::uint32_t> prefix(static_cast<std::size_t>(width + 1) * stride);
            for (int y = begin; y < end; ++y) {
                std::fill(prefix.begin(), prefix.begin() + stride, 0u);
                for (int x = 0; x < width; ++x) {
                    const std::uint16_t* c = costs.at(x, y);
                    const std::uint32_t* before = prefix.data() + static_cast<std::size_t>(x) * stride;
                    std::uint32_t* after = prefix.data() + static_cast<std::size_t>(x + 1) * stride;
                    for (int d = 0; d < stride; d += kLanes) {
                        cv::v_uint32x4 lo, hi;
                        cv::v_expand(cv::v_load(c + d), lo, hi);
                        cv::v_store(after + d, cv::v_load(before + d) + lo);
                        cv::v_store(after + d + kLanes32, cv::v_load(before + d + kLanes32) + hi);
                    }
                }
                const std::uint8_t* left = arms.left.ptr<std::uint8_t>(y);
                const std::uint8_t* right = arms.right.ptr<std::uint8_t>(y);
                for (int x = 0; x < width; ++x) {
                    const std::uint32_t* a = prefix.data() + static_cast<std::size_t>(x - left[x]) * stride;
                    const std::uint32_t* b = prefix.data() + static_cast<std::size_t>(x + right[x] + 1) * stride;
                    const cv::v_float32x4 inverse = cv::v_setall_f32(1.0f / static_cast<float>(left[x] + right[x] + 1));
                    std::uint16_t* out = costs.at(x, y);
                    for (int d = 0; d < stride; d += kLanes) {
                        const cv::v_uint32x4 lo = cv::v_load(b + d) - cv::v_load(a + d);
                        const cv::v_uint32x4 hi = cv::v_load(b + d + kLanes32) - cv::v_load(a + d + kLanes32);
                        cv::v_store(out + d, meanLanes(lo, hi, inverse));
                    }
                }
            }
        });
        // Vertical pass, costs -> scratch: region sum = sum over the vertical arm of count x mean.
        forEachStripe(height, [&](int, int begin, int end) {
            std::vector<std::uint32_t> acc(static_cast<std::size_t>(stride));
            for (int y = begin; y < end; ++y) {
                const std::uint8_t* up = arms.up.ptr<std::uint8_t>(y);
                const std::uint8_t* down = arms.down.ptr<std::uint8_t>(y);
                for (int x = 0; x < width; ++x) {
                    std::fill(acc.begin(), acc.end(), 0u);
                    int count = 0;
                    for (int yy = y - up[x]; yy <= y + down[x]; ++yy) {
                        const int n = arms.left.at<std::uint8_t>(yy, x) + arms.right.at<std::uint8_t>(yy, x) + 1;
                        count += n;
                        const cv::v_uint16x8 weight = cv::v_setall_u16(static_cast<std::uint16_t>(n));
                        const std::uint16_t* c = costs.at(x, yy);
                        for (int d = 0; d < stride; d += kLanes) {
                            cv::v_uint32x4 lo, hi;
                            cv::v_mul_expand(cv::v_load(c + d), weight, lo, hi);
                            cv::v_store(acc.data() + d, cv::v_load(acc.data() + d) + lo);
                            cv::v_store(acc.data() + d + kLanes32, cv::v_load(acc.data() + d + kLanes32) + hi);
                        }
                    }
                    const cv::v_float32x4 inverse = cv::v_setall_f32(1.0f / static_cast<float>(count));
                    std::uint16_t* out = scratch.at(x, y);
                    for (int d = 0; d < stride; d += kLanes) {
                        cv::v_store(out + d, meanLanes(cv::v_load(acc.data() + d), cv::v_load(acc.data() + d + kLanes32),
                                                       inverse));
                    }
                }
            }
        });
        std::swap(costs.data, scratch.data);
    }
    restorePadding(costs);
}

void aggregateCrossReference(const CrossArms& arms, int iterations, CostVolume& costs) {
    const int width = costs.width, height = costs.height;
    CostVolume horizontal;
    horizontal.create(width, height, costs.disparities);
    for (int iteration = 0; iteration < iterations; ++iteration) {
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x) {
                const int l = arms.left.at<std::uint8_t>(y, x), r = arms.right.at<std::uint8_t>(y, x);
                const float inverse = 1.0f / static_cast<float>(l + r + 1);
                for (int d = 0; d < costs.stride; ++d) {
                    std::uint32_t sum = 0;
                    for (int xx = x - l; xx <= x + r; ++xx) sum += costs.at(xx, y)[d];
                    horizontal.at(x, y)[d] = roundedMean(sum, inverse);
                }
            }
        for (int y = 0; y < height; ++y)
            for (int x = 0; x < width; ++x) {
                int count = 0;
                for (int yy = y - arms.up.at<std::uint8_t>(y, x); yy <= y + arms.down.at<std::uint8_t>(y, x); ++yy) {
                    count += arms.left.at<std::uint8_t>(yy, x) + arms.right.at<std::uint8_t>(yy, x) + 1;
                }
                const float inverse = 1.0f / static_cast<float>(count);
                for (int d = 0; d < costs.stride; ++d) {
                    std::uint32_t sum = 0;
                    for (int yy = y - arms.up.at<std::uint8_t>(y, x); yy <= y + arms.down.at<std::uint8_t>(y, x); ++yy) {
                        const int n = arms.left.at<std::uint8_t>(yy, x) + arms.right.at<std::uint8_t>(yy, x) + 1;
                        sum += static_cast<std::uint32_t>(n) * horizontal.at(x, yy)[d];
                    }
                    costs.at(x, y)[d] = roundedMean(sum, inverse);
                }
            }
    }
    restorePadding(costs);
}

}  // namespace icewatch::stereo::detail
