#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

namespace icewatch::volume {

// The seed paper's statistical outlier removal: for every point its k nearest neighbours in the
// plane (x, y); the point goes when |z - mean(z_neighbours)| > theta · σ(z_neighbours).
// Returns one flag per point, 1 = keep. A k-d tree (nanoflann) makes it O(n log n).
std::vector<std::uint8_t> knnKeepMask(const std::vector<cv::Point3d>& points, int k, double theta);

}  // namespace icewatch::volume
