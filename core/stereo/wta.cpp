// Winner-take-all: the disparity of least aggregated cost, for the left view and, from the same
// volume read along its diagonals, for the right view (the right pixel x sees the left pixel
// x + d at disparity d). Ties go to the smaller disparity.
//
// The optimised kernel packs each candidate as (cost << 16) | d in 32 bits, so one unsigned
// minimum finds the least cost and, among equal costs, the smallest disparity: the left view
// reduces a pixel's packed candidates, the right view keeps a running packed minimum per right
// pixel and updates a vector of them at once (with n lanes, the candidates of left pixel x at
// d .. d+n-1 belong to the right pixels x-d .. x-d-n+1, a reversed run).
#include <algorithm>

#include "core/common/simd.hpp"

#include "core/stereo/stages.hpp"

namespace icewatch::stereo::detail {

namespace {

constexpr int kLanes32 = cv::v_uint32::nlanes;  // the widest vector: 8 with AVX2, 4 with SSE or NEON
alignas(64) constexpr std::uint32_t kLaneIndex[16] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15};
static_assert(kLanes32 <= 16);
constexpr std::uint32_t kNoCandidate = 0xFFFFFFFFu;

// Scalar tail and the pixels near the left border, where fewer than `disparities` candidates are
// valid: the same packed minima, one candidate at a time.
inline void updateScalar(const std::uint16_t* c, int x, int d0, int d1, std::uint32_t& leftBest, std::uint32_t* rightBest) {
    for (int d = d0; d < d1; ++d) {
        const std::uint32_t packed = (static_cast<std::uint32_t>(c[d]) << 16) | static_cast<std::uint32_t>(d);
        leftBest = std::min(leftBest, packed);
        std::uint32_t& r = rightBest[x - d];
        r = std::min(r, packed);
    }
}

}  // namespace

void winnerTakesAll(const CostVolume& costs, cv::Mat& leftDisparity, cv::Mat& rightDisparity) {
    const int width = costs.width, disparities = costs.disparities;
    leftDisparity.create(costs.height, width, CV_16SC1);
    rightDisparity.create(costs.height, width, CV_16SC1);
    forEachStripe(costs.height, [&](int, int begin, int end) {
        std::vector<std::uint32_t> rightBest(static_cast<std::size_t>(width));
        const cv::v_uint32 step = cv::vx_setall_u32(kLanes32);
        for (int y = begin; y < end; ++y) {
            auto* left = leftDisparity.ptr<std::int16_t>(y);
            std::fill(rightBest.begin(), rightBest.end(), kNoCandidate);
            for (int x = 0; x < width; ++x) {
                const std::uint16_t* c = costs.at(x, y);
                const int valid = std::min(disparities, x + 1);
                const int vectorEnd = valid / kLanes32 * kLanes32;
                std::uint32_t leftBest = kNoCandidate;
                cv::v_uint32 best = cv::vx_setall_u32(kNoCandidate);
                cv::v_uint32 index = cv::vx_load(kLaneIndex);
                for (int d = 0; d < vectorEnd; d += kLanes32) {
                    const cv::v_uint32 packed = (cv::vx_load_expand(c + d) << 16) | index;
                    best = cv::v_min(best, packed);
                    // Right pixels x-d-n+1 .. x-d in memory order are candidates d+n-1 .. d.
                    std::uint32_t* r = rightBest.data() + (x - d - (kLanes32 - 1));
                    cv::v_store(r, cv::v_min(cv::vx_load(r), cv::v_reverse(packed)));
                    index += step;
                }
                leftBest = std::min(leftBest, cv::v_reduce_min(best));
                updateScalar(c, x, vectorEnd, valid, leftBest, rightBest.data());
                left[x] = static_cast<std::int16_t>(leftBest & 0xFFFFu);
            }
            auto* right = rightDisparity.ptr<std::int16_t>(y);
            for (int x = 0; x < width; ++x) {
                right[x] = rightBest[static_cast<std::size_t>(x)] == kNoCandidate
                               ? std::int16_t{-1}
                               : static_cast<std::int16_t>(rightBest[static_cast<std::size_t>(x)] & 0xFFFFu);
            }
        }
    });
}

void winnerTakesAllReference(const CostVolume& costs, cv::Mat& leftDisparity, cv::Mat& rightDisparity) {
    const int width = costs.width, disparities = costs.disparities;
    leftDisparity.create(costs.height, width, CV_16SC1);
    rightDisparity.create(costs.height, width, CV_16SC1);
    for (int y = 0; y < costs.height; ++y)
        for (int x = 0; x < width; ++x) {
            // Left pixel x: candidates d = 0 .. min(D, x + 1) - 1.
            const std::uint16_t* c = costs.at(x, y);
            int bestD = 0;
            for (int d = 1; d < std::min(disparities, x + 1); ++d)
                if (c[d] < c[bestD]) bestD = d;
            leftDisparity.at<std::int16_t>(y, x) = static_cast<std::int16_t>(bestD);
            // Right pixel x: candidates d with x + d inside the image.
            int bestRight = -1;
            for (int d = 0; d < disparities && x + d < width; ++d) {
                if (costs.at(x + d, y)[d] < (bestRight < 0 ? 0x10000 : costs.at(x + bestRight, y)[bestRight])) {
                    bestRight = d;
                }
            }
            rightDisparity.at<std::int16_t>(y, x) = static_cast<std::int16_t>(bestRight);
        }
}

}  // namespace icewatch::stereo::detail
