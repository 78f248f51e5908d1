#pragma once
// Parallel work split into a fixed number of bands whatever the core count, so that no result
// depends on how many threads ran it (the matcher's stripes of rows, the volume chain's bands of
// samples, points or RANSAC draws).

#include <cstddef>

#include <opencv2/core.hpp>

namespace icewatch {

inline constexpr int kFixedBands = 16;

// Runs fn(band, begin, end) over the kFixedBands slices [begin, end) of [0, count) that are not
// empty, in parallel.
template <class F>
void forEachFixedBand(std::size_t count, const F& fn) {
    cv::parallel_for_(cv::Range(0, kFixedBands), [&](const cv::Range& bands) {
        for (int band = bands.start; band < bands.end; ++band) {
            const std::size_t begin = count * static_cast<std::size_t>(band) / kFixedBands;
            const std::size_t end = count * static_cast<std::size_t>(band + 1) / kFixedBands;
            if (begin < end) fn(band, begin, end);
        }
    }, kFixedBands);
}

}  // namespace icewatch
