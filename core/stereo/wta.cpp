// Winner-take-all: the disparity of least aggregated cost, for the left view and, from the same
// volume read along its diagonals, for the right view (the right pixel x sees the left pixel
// x + d at disparity d). Ties go to the smaller disparity.
#include "core/stereo/stages.hpp"

namespace icewatch::stereo::detail {

void winnerTakesAll(const CostVolume& costs, cv::Mat& leftDisparity, cv::Mat& rightDisparity) {
    const int width = costs.width, disparities = costs.disparities;
    leftDisparity.create(costs.height, width, CV_16SC1);
    rightDisparity.create(costs.height, width, CV_16SC1);
    forEachStripe(costs.height, [&](int, int begin, int end) {
        std::vector<int> best(static_cast<std::size_t>(width));
        for (int y = begin; y < end; ++y) {
            auto* left = leftDisparity.ptr<std::int16_t>(y);
            auto* right = rightDisparity.ptr<std::int16_t>(y);
            std::fill(best.begin(), best.end(), 0x7FFFFFFF);
            std::fill(right, right + width, std::int16_t{-1});
            for (int x = 0; x < width; ++x) {
                const std::uint16_t* c = costs.at(x, y);
                int bestCost = c[0], bestD = 0;
                const int valid = std::min(disparities, x + 1);
                for (int d = 0; d < valid; ++d) {
                    if (c[d] < bestCost) {
                        bestCost = c[d];
                        bestD = d;
                    }
                    // Right pixel x - d: keep the smallest disparity among equal costs.
                    auto& b = best[static_cast<std::size_t>(x - d)];
                    if (c[d] < b || (c[d] == b && d < right[x - d])) {
                        b = c[d];
                        right[x - d] = static_cast<std::int16_t>(d);
                    }
                }
                left[x] = static_cast<std::int16_t>(bestD);
            }
        }
    });
}

}  // namespace icewatch::stereo::detail
