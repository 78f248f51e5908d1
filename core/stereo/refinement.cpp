// Disparity refinement after the winner-take-all, following Mei et al. 2011 as the seed paper
// does: left-right check, iterative region voting inside the cross support regions,
// interpolation of what is left, sub-pixel refinement.
//
// Sub-pixel fit: the equiangular ("V") fit of Shimizu and Okutomi, not the parabola. The
// aggregated costs here are sums of robust, L1-like terms whose minimum is a kink, not a smooth
// bowl; a parabola through such a kink pulls every estimate towards the integer ("pixel
// locking", a bias of up to ~0.15 px in the middle of each pixel), while the V fit has the kink's
// shape and is unbiased for it. The ice volume is a mean of sub-pixel differences (see
// docs/HBVCAM.md in the shared folder), so bias matters more than noise; the matcher tests
// measure the bias on a synthetic fractional shift.
#include <algorithm>
#include <cmath>

#include "core/stereo/matcher.hpp"
#include "core/stereo/stages.hpp"

namespace icewatch::stereo::detail {

cv::Mat leftRightCheck(const cv::Mat& leftDisparity, const cv::Mat& rightDisparity, int disparities,
                       int maxDifference) {
    CV_Assert(leftDisparity.type() == CV_16SC1 && rightDisparity.type() == CV_16SC1);
    cv::Mat labels(leftDisparity.size(), CV_8UC1);
    const int width = leftDisparity.cols;
    forEachStripe(leftDisparity.rows, [&](int, int begin, int end) {
        for (int y = begin; y < end; ++y) {
            const auto* left = leftDisparity.ptr<std::int16_t>(y);
            const auto* right = rightDisparity.ptr<std::int16_t>(y);
            auto* label = labels.ptr<std::uint8_t>(y);
            for (int x = 0; x < width; ++x) {
                const int d = left[x];
                if (d >= 0 && x - d >= 0 && std::abs(d - right[x - d]) <= maxDifference) {
                    label[x] = kReliable;
                    continue;
                }
                // Mei: if the epipolar line offers some consistent match (a right pixel that
                // maps back here), the pixel was seen by both eyes and merely mismatched;
                // otherwise it is hidden from the right eye.
                label[x] = kOccluded;
                for (int t = 0; t < std::min(disparities, x + 1); ++t) {
                    if (right[x - t] == t) {
                        label[x] = kMismatched;
                        break;
                    }
                }
            }
        }
    });
    return labels;
}

int regionVoting(const CrossArms& arms, const Parameters& parameters, cv::Mat& disparity, cv::Mat& labels) {
    CV_Assert(disparity.type() == CV_16SC1 && labels.type() == CV_8UC1);
    double maxValue = 0.0;
    cv::minMaxLoc(disparity, nullptr, &maxValue);
    const int bins = static_cast<int>(maxValue) + 1;
    int filledTotal = 0;
    for (int iteration = 0; iteration < parameters.votingIterations; ++iteration) {
        // Jacobi style: votes read the previous iteration's map, so the result does not depend on
        // the order (or the thread) in which pixels are visited.
        const cv::Mat before = disparity.clone();
        const cv::Mat labelsBefore = labels.clone();
        std::vector<int> filledPerStripe(kStripes, 0);
        forEachStripe(disparity.rows, [&](int stripe, int begin, int end) {
            std::vector<int> histogram(static_cast<std::size_t>(bins));
            for (int y = begin; y < end; ++y)
                for (int x = 0; x < disparity.cols; ++x) {
                    if (labelsBefore.at<std::uint8_t>(y, x) == kReliable) continue;
                    std::fill(histogram.begin(), histogram.end(), 0);
                    int reliable = 0;
                    for (int yy = y - arms.up.at<std::uint8_t>(y, x); yy <= y + arms.down.at<std::uint8_t>(y, x); ++yy) {
                        const auto* d = before.ptr<std::int16_t>(yy);
                        const auto* l = labelsBefore.ptr<std::uint8_t>(yy);
                        const int x0 = x - arms.left.at<std::uint8_t>(yy, x), x1 = x + arms.right.at<std::uint8_t>(yy, x);
                        for (int xx = x0; xx <= x1; ++xx) {
                            if (l[xx] != kReliable) continue;
                            ++histogram[static_cast<std::size_t>(d[xx])];
                            ++reliable;
                        }
                    }
                    if (reliable <= parameters.votingMinCount) continue;
                    const auto top = std::max_element(histogram.begin(), histogram.end());
                    if (*top <= parameters.votingMinRatio * reliable) continue;
                    disparity.at<std::int16_t>(y, x) = static_cast<std::int16_t>(top - histogram.begin());
                    labels.at<std::uint8_t>(y, x) = kReliable;
                    ++filledPerStripe[static_cast<std::size_t>(stripe)];
                }
        });
        int filled = 0;
        for (int f : filledPerStripe) filled += f;
        filledTotal += filled;
        if (filled == 0) break;
    }
    return filledTotal;
}

void interpolateOutliers(cv::Mat& disparity, cv::Mat& labels) {
    CV_Assert(disparity.type() == CV_16SC1 && labels.type() == CV_8UC1);
    const int width = disparity.cols;
    forEachStripe(disparity.rows, [&](int, int begin, int end) {
        std::vector<int> leftValue(static_cast<std::size_t>(width)), rightValue(static_cast<std::size_t>(width));
        for (int y = begin; y < end; ++y) {
            auto* d = disparity.ptr<std::int16_t>(y);
            auto* l = labels.ptr<std::uint8_t>(y);
            int last = -1;
            for (int x = 0; x < width; ++x) {
                if (l[x] == kReliable) last = d[x];
                leftValue[static_cast<std::size_t>(x)] = last;
            }
            last = -1;
            for (int x = width - 1; x >= 0; --x) {
                if (l[x] == kReliable) last = d[x];
                rightValue[static_cast<std::size_t>(x)] = last;
            }
            for (int x = 0; x < width; ++x) {
                if (l[x] == kReliable) continue;
                const int a = leftValue[static_cast<std::size_t>(x)], b = rightValue[static_cast<std::size_t>(x)];
                int value;
                if (a < 0 || b < 0) {
                    value = std::max(a, b);  // only one side exists (or none: stays invalid)
                } else if (l[x] == kOccluded) {
                    // Hidden from the right eye by something nearer on its right: the surface it
                    // belongs to continues from the left.
                    value = a;
                } else {
                    value = std::min(a, b);
                }
                d[x] = static_cast<std::int16_t>(value);
            }
        }
    });
}

float subpixelOffset(int costMinus, int cost, int costPlus) {
    // Equiangular fit: two lines of equal and opposite slope through the three costs, the slope
    // taken from the steeper side.
    const int steeper = std::max(costMinus, costPlus) - cost;
    if (steeper <= 0) return 0.0f;
    const float offset = 0.5f * static_cast<float>(costMinus - costPlus) / static_cast<float>(steeper);
    return std::clamp(offset, -0.5f, 0.5f);
}

cv::Mat subpixelRefine(const cv::Mat& disparity, const CostVolume& costs) {
    cv::Mat refined(disparity.size(), CV_32FC1);
    forEachStripe(disparity.rows, [&](int, int begin, int end) {
        for (int y = begin; y < end; ++y) {
            const auto* d = disparity.ptr<std::int16_t>(y);
            auto* out = refined.ptr<float>(y);
            for (int x = 0; x < disparity.cols; ++x) {
                if (d[x] < 0) {
                    out[x] = kInvalidDisparity;
                    continue;
                }
                out[x] = d[x];
                if (d[x] < 1 || d[x] + 1 >= std::min(costs.disparities, x + 1)) continue;
                const std::uint16_t* c = costs.at(x, y) + d[x];
                // Only a local minimum has a shape to fit; filled-in pixels may sit elsewhere.
                if (c[0] > c[-1] || c[0] > c[1]) continue;
                out[x] += subpixelOffset(c[-1], c[0], c[1]);
            }
        }
    });
    return refined;
}

}  // namespace icewatch::stereo::detail
