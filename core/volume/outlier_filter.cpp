// k-NN outlier filter. Neighbours are searched in the plane only, as the paper does: the height is
// the quantity being judged, so it must not decide who the neighbours are.
#include "core/volume/outlier_filter.hpp"

#include <cmath>

#include <nanoflann.hpp>

#include "core/common/error.hpp"

namespace icewatch::volume {

namespace {

struct PlaneCloud {
    const std::vector<cv::Point3d>& points;
    std::size_t kdtree_get_point_count() const { return points.size(); }
    double kdtree_get_pt(std::size_t i, std::size_t dim) const { return dim == 0 ? points[i].x : points[i].y; }
    template <class Box>
    bool kdtree_get_bbox(Box&) const {
        return false;
    }
};

using PlaneTree =
    nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, PlaneCloud>, PlaneCloud, 2, std::size_t>;

}  // namespace

std::vector<std::uint8_t> knnKeepMask(const std::vector<cv::Point3d>& points, int k, double theta) {
    if (k < 2 || theta <= 0) {
        throw InvalidInput("k-NN filter: k must be at least 2 and theta positive");
    }
    std::vector<std::uint8_t> keep(points.size(), 1);
    if (points.size() <= static_cast<std::size_t>(k)) {
        return keep;
    }
    const PlaneCloud cloud{points};
    const PlaneTree tree(2, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(16));
    const auto wanted = static_cast<std::size_t>(k) + 1;  // the point itself comes first
    std::vector<std::size_t> indices(wanted);
    std::vector<double> distances(wanted);
    for (std::size_t i = 0; i < points.size(); ++i) {
        const double query[2] = {points[i].x, points[i].y};
        const std::size_t found = tree.knnSearch(query, wanted, indices.data(), distances.data());
        double sum = 0, sumSquares = 0;
        int n = 0;
        for (std::size_t j = 0; j < found; ++j) {
            if (indices[j] == i) continue;
            const double z = points[indices[j]].z;
            sum += z;
            sumSquares += z * z;
            ++n;
        }
        if (n < 2) continue;
        const double mean = sum / n;
        const double sigma = std::sqrt(std::max(0.0, sumSquares / n - mean * mean));
        if (std::abs(points[i].z - mean) > theta * sigma) {
            keep[i] = 0;
        }
    }
    return keep;
}

}  // namespace icewatch::volume
