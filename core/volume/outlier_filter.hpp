#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

namespace icewatch::volume {

// The seed paper's statistical outlier removal: for every point its k nearest other points in the
// plane (x, y), a tie in distance going to the lower index; the point goes when
// |z - mean(z_neighbours)| > theta · σ(z_neighbours), both summed nearest first. Returns one flag
// per point, 1 = keep (every point when there are k or fewer). Throws InvalidInput on k < 2,
// theta <= 0 or a point whose x or y is not finite.
// The points are searched in a grid of buckets, in a fixed number of bands of points run in
// parallel: the result does not depend on the thread count.
std::vector<std::uint8_t> knnKeepMask(const std::vector<cv::Point3d>& points, int k, double theta);
// The same by brute force, O(n²): the plain reference the fast search is tested against.
std::vector<std::uint8_t> knnKeepMaskReference(const std::vector<cv::Point3d>& points, int k, double theta);

}  // namespace icewatch::volume
