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
// textureless areas. Where a column has few outliers with small regions, visiting them is the
// cheaper way and is kept: each column takes whichever its arms say costs less (both are exact).
//
// Counts are 16-bit and may wrap along the column: a difference of wrapped prefix sums is exact
// as long as the region's true count fits, and a region holds at most 255 x 255 pixels (arms are
// at most 127 long).
//
// After the first pass only the outliers whose region gained a reliable pixel in the pass before
// vote again. The others would count the same histogram as last time, which lost (a winner is no
// longer an outlier), and lose again: skipping them changes no result. Later passes fill few
// pixels, so most of their outliers are skipped; whether a region gained one is a sum of row
// segments of a per-row prefix count of the pixels that became reliable.
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
    cv::Mat previousLabels;  // what the last pass read; empty before the first pass
    cv::Mat gained(height, width + 1, CV_32SC1);  // per row: prefix count of pixels that became reliable
    return iterateVoting(parameters.votingIterations, disparity, labels, [&](const cv::Mat& before,
                                                                             const cv::Mat& labelsBefore,
                                                                             std::vector<int>& filledPerStripe) {
        const bool everyOutlierVotes = previousLabels.empty();
        if (!everyOutlierVotes) {
            forEachStripe(height, [&](int, int begin, int end) {
                for (int y = begin; y < end; ++y) {
                    const auto* now = labelsBefore.ptr<std::uint8_t>(y);
                    const auto* then = previousLabels.ptr<std::uint8_t>(y);
                    auto* count = gained.ptr<std::int32_t>(y);
                    count[0] = 0;
                    for (int x = 0; x < width; ++x) count[x + 1] = count[x] + (now[x] == kReliable && then[x] != kReliable);
                }
            });
        }
        // Whether the region of outlier (x, y) gained a reliable pixel in the last pass.
        auto regionGained = [&](int x, int y) {
            for (int yy = y - arms.up.at<std::uint8_t>(y, x); yy <= y + arms.down.at<std::uint8_t>(y, x); ++yy) {
                const auto* count = gained.ptr<std::int32_t>(yy);
                if (count[x + arms.right.at<std::uint8_t>(yy, x) + 1] != count[x - arms.left.at<std::uint8_t>(yy, x)]) {
                    return true;
                }
            }
            return false;
        };
        forEachStripe(width, [&](int stripe, int begin, int end) {
            std::vector<std::uint16_t> prefix(static_cast<std::size_t>(height + 1) * pitch);
            std::vector<int> reliablePrefix(static_cast<std::size_t>(height + 1));
            std::vector<std::uint16_t> histogram(static_cast<std::size_t>(pitch));
            std::vector<int> outliers;
            // Reliable pixels of the horizontal arm of (x, y) into counts; returns how many.
            // Neighbours mostly share a disparity, and incrementing the same counter pixel after
            // pixel waits on the previous increment's store every time: equal disparities are
            // counted as runs in a register and added once per run.
            auto countSegment = [&](int x, int y, std::uint16_t* counts) {
                const auto* d = before.ptr<std::int16_t>(y);
                const auto* l = labelsBefore.ptr<std::uint8_t>(y);
                const int x0 = x - arms.left.at<std::uint8_t>(y, x), x1 = x + arms.right.at<std::uint8_t>(y, x);
                int reliable = 0, runValue = 0, runLength = 0;
                for (int xx = x0; xx <= x1; ++xx) {
                    if (l[xx] != kReliable) continue;
                    ++reliable;
                    if (d[xx] == runValue) {
                        ++runLength;
                        continue;
                    }
                    counts[runValue] = static_cast<std::uint16_t>(counts[runValue] + runLength);
                    runValue = d[xx];
                    runLength = 1;
                }
                counts[runValue] = static_cast<std::uint16_t>(counts[runValue] + runLength);
                return reliable;
            };
            // The vote of outlier (x, y) on its region's histogram (whole vectors of counts).
            auto vote = [&](int x, int y, const std::uint16_t* counts, int reliable) {
                if (reliable <= parameters.votingMinCount) return;
                cv::v_uint16 most = cv::vx_setzero_u16();
                for (int b = 0; b < pitch; b += kLanes) most = cv::v_max(most, cv::vx_load(counts + b));
                const int best = cv::v_reduce_max(most);
                if (best <= parameters.votingMinRatio * reliable) return;
                // The smallest disparity with the most votes, as std::max_element picks.
                const auto winner = std::find(counts, counts + bins, best) - counts;
                disparity.at<std::int16_t>(y, x) = static_cast<std::int16_t>(winner);
                labels.at<std::uint8_t>(y, x) = kReliable;
                ++filledPerStripe[static_cast<std::size_t>(stripe)];
            };
            for (int x = begin; x < end; ++x) {
                // This column's outliers, the rows their regions span, and what each way costs:
                // visiting every region pixel, or a prefix row (a vector copy and one segment)
                // for every row spanned.
                outliers.clear();
                int first = height, last = -1;
                long long directCost = 0;
                for (int y = 0; y < height; ++y) {
                    if (labelsBefore.at<std::uint8_t>(y, x) == kReliable) continue;
                    if (!everyOutlierVotes && !regionGained(x, y)) continue;
                    outliers.push_back(y);
                    const int up = arms.up.at<std::uint8_t>(y, x), down = arms.down.at<std::uint8_t>(y, x);
                    first = std::min(first, y - up);
                    last = std::max(last, y + down);
                    directCost += static_cast<long long>(up + down + 1) *
                                      (arms.left.at<std::uint8_t>(y, x) + arms.right.at<std::uint8_t>(y, x) + 1) +
                                  pitch;
                }
                if (outliers.empty()) continue;
                long long prefixCost = 0;
                for (int y = first; y <= last; ++y) {
                    prefixCost += pitch / 4 + arms.left.at<std::uint8_t>(y, x) + arms.right.at<std::uint8_t>(y, x) + 1;
                }
                if (directCost <= prefixCost) {
                    for (const int y : outliers) {
                        std::fill(histogram.begin(), histogram.end(), std::uint16_t{0});
                        int reliable = 0;
                        for (int yy = y - arms.up.at<std::uint8_t>(y, x); yy <= y + arms.down.at<std::uint8_t>(y, x); ++yy) {
                            reliable += countSegment(x, yy, histogram.data());
                        }
                        vote(x, y, histogram.data(), reliable);
                    }
                    continue;
                }
                // V over rows first .. last (prefix row i holds the rows before first + i).
                std::fill(prefix.begin(), prefix.begin() + pitch, std::uint16_t{0});
                reliablePrefix[0] = 0;
                for (int y = first; y <= last; ++y) {
                    const auto i = static_cast<std::size_t>(y - first);
                    std::uint16_t* next = prefix.data() + (i + 1) * pitch;
                    std::copy(next - pitch, next, next);
                    reliablePrefix[i + 1] = reliablePrefix[i] + countSegment(x, y, next);
                }
                for (const int y : outliers) {
                    const auto i0 = static_cast<std::size_t>(y - arms.up.at<std::uint8_t>(y, x) - first);
                    const auto i1 = static_cast<std::size_t>(y + arms.down.at<std::uint8_t>(y, x) + 1 - first);
                    const std::uint16_t* top = prefix.data() + i1 * pitch;
                    const std::uint16_t* bottom = prefix.data() + i0 * pitch;
                    for (int b = 0; b < pitch; b += kLanes) {
                        cv::v_store(histogram.data() + b, cv::v_sub_wrap(cv::vx_load(top + b), cv::vx_load(bottom + b)));
                    }
                    vote(x, y, histogram.data(), reliablePrefix[i1] - reliablePrefix[i0]);
                }
            }
        });
        previousLabels = labelsBefore;  // a copy of its own: iterateVoting clones before every pass
    });
}

}  // namespace icewatch::stereo::detail
