// Iterative region voting (Mei et al. 2011), the optimised kernel; regionVotingReference in
// refinement.cpp is the plain definition and gives the same integers.
//
// An outlier p takes the most frequent reliable disparity of its support region when the region
// holds more than τ_n reliable pixels and that disparity more than τ_r of them. The region is the
// union of the horizontal arms of the pixels on p's vertical arm, so its histogram is a sum along
// column x of per-pixel row-segment histograms H(x, y). A column prefix of those,
// V(y) = Σ_{y' < y} H(x, y'), gives every region's histogram as one difference of two rows,
// V(y + down + 1) - V(y - up), whatever the region's size; the plain version visits every pixel
// of every outlier's region, which dominated the matcher's time on 1280x720 frames with large
// textureless areas.
//
// Counts are 16-bit and may wrap along the column: a difference of wrapped prefix sums is exact
// as long as the region's true count fits, and a region holds at most 255 x 255 pixels (arms are
// at most 127 long).
#include <algorithm>

#include "core/common/simd.hpp"

#include "core/stereo/stages.hpp"

namespace icewatch::stereo::detail {

int regionVoting(const CrossArms& arms, const Parameters& parameters, cv::Mat& disparity, cv::Mat& labels) {
    CV_Assert(disparity.type() == CV_16SC1 && labels.type() == CV_8UC1);
    CV_Assert(disparity.size() == labels.size() && arms.up.size() == disparity.size());
    const int width = disparity.cols, height = disparity.rows;
    double maxValue = 0.0;
    cv::minMaxLoc(disparity, nullptr, &maxValue);
    const int bins = static_cast<int>(maxValue) + 1;
    constexpr int kLanes = cv::v_uint16::nlanes;
    const int pitch = (bins + kLanes - 1) / kLanes * kLanes;  // one prefix row, whole vectors
    return iterateVoting(parameters.votingIterations, disparity, labels, [&](const cv::Mat& before,
                                                                             const cv::Mat& labelsBefore,
                                                                             std::vector<int>& filledPerStripe) {
        forEachStripe(width, [&](int stripe, int begin, int end) {
            std::vector<std::uint16_t> prefix(static_cast<std::size_t>(height + 1) * pitch);
            std::vector<int> reliablePrefix(static_cast<std::size_t>(height + 1));
            std::vector<std::uint16_t> histogram(static_cast<std::size_t>(pitch));
            for (int x = begin; x < end; ++x) {
                bool anyOutlier = false;
                for (int y = 0; y < height && !anyOutlier; ++y) anyOutlier = labelsBefore.at<std::uint8_t>(y, x) != kReliable;
                if (!anyOutlier) continue;
                // V and the reliable count along the column.
                std::fill(prefix.begin(), prefix.begin() + pitch, std::uint16_t{0});
                reliablePrefix[0] = 0;
                for (int y = 0; y < height; ++y) {
                    std::uint16_t* next = prefix.data() + static_cast<std::size_t>(y + 1) * pitch;
                    std::copy(next - pitch, next, next);
                    const auto* d = before.ptr<std::int16_t>(y);
                    const auto* l = labelsBefore.ptr<std::uint8_t>(y);
                    const int x0 = x - arms.left.at<std::uint8_t>(y, x), x1 = x + arms.right.at<std::uint8_t>(y, x);
                    int reliable = 0;
                    for (int xx = x0; xx <= x1; ++xx) {
                        if (l[xx] != kReliable) continue;
                        ++next[d[xx]];
                        ++reliable;
                    }
                    reliablePrefix[static_cast<std::size_t>(y + 1)] = reliablePrefix[static_cast<std::size_t>(y)] + reliable;
                }
                for (int y = 0; y < height; ++y) {
                    if (labelsBefore.at<std::uint8_t>(y, x) == kReliable) continue;
                    const int y0 = y - arms.up.at<std::uint8_t>(y, x), y1 = y + arms.down.at<std::uint8_t>(y, x) + 1;
                    const int reliable = reliablePrefix[static_cast<std::size_t>(y1)] - reliablePrefix[static_cast<std::size_t>(y0)];
                    if (reliable <= parameters.votingMinCount) continue;
                    const std::uint16_t* top = prefix.data() + static_cast<std::size_t>(y1) * pitch;
                    const std::uint16_t* bottom = prefix.data() + static_cast<std::size_t>(y0) * pitch;
                    cv::v_uint16 most = cv::vx_setzero_u16();
                    for (int b = 0; b < pitch; b += kLanes) {
                        const cv::v_uint16 count = cv::v_sub_wrap(cv::vx_load(top + b), cv::vx_load(bottom + b));
                        cv::v_store(histogram.data() + b, count);
                        most = cv::v_max(most, count);
                    }
                    const int best = cv::v_reduce_max(most);
                    if (best <= parameters.votingMinRatio * reliable) continue;
                    // The smallest disparity with the most votes, as std::max_element picks.
                    const auto winner = std::find(histogram.begin(), histogram.begin() + bins, best) - histogram.begin();
                    disparity.at<std::int16_t>(y, x) = static_cast<std::int16_t>(winner);
                    labels.at<std::uint8_t>(y, x) = kReliable;
                    ++filledPerStripe[static_cast<std::size_t>(stripe)];
                }
            }
        });
    });
}

}  // namespace icewatch::stereo::detail
