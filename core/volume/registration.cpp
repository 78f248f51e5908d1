// What the registration rests on (how much of the object the unchanged surface spans), and where
// it puts the baseline's pixels in the current capture.
#include "core/volume/registration.hpp"

#include <algorithm>
#include <limits>
#include <optional>

#include "core/volume/height_grid.hpp"

namespace icewatch::volume {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
}  // namespace

double supportSpanPercent(const std::vector<cv::Vec3d>& samples, const std::vector<std::uint8_t>& support,
                          const RigidTransform& transform, const PlaneFrame& plane) {
    constexpr int kBins = 10;
    std::vector<cv::Point2d> all;
    for (const cv::Vec3d& sample : samples) {
        const cv::Point3d local = plane.toPlane(transform.apply(sample));
        all.emplace_back(local.x, local.y);
    }
    if (all.size() < 2) return 0.0;
    double share = 1.0;
    for (int axis = 0; axis < 2; ++axis) {
        auto coordinate = [axis](const cv::Point2d& q) { return axis == 0 ? q.x : q.y; };
        double lo = coordinate(all.front()), hi = lo;
        for (const cv::Point2d& q : all) {
            lo = std::min(lo, coordinate(q));
            hi = std::max(hi, coordinate(q));
        }
        std::vector<int> region(kBins, 0), supported(kBins, 0);
        for (std::size_t i = 0; i < all.size(); ++i) {
            const int bin = std::clamp(static_cast<int>((coordinate(all[i]) - lo) / std::max(1e-9, hi - lo) * kBins), 0,
                                       kBins - 1);
            ++region[bin];
            if (support.empty() || support[i]) ++supported[bin];
        }
        int covered = 0, occupied = 0;
        for (int bin = 0; bin < kBins; ++bin) {
            if (region[bin] == 0) continue;
            ++occupied;
            if (3 * supported[bin] >= region[bin]) ++covered;
        }
        share = std::min(share, occupied > 0 ? static_cast<double>(covered) / occupied : 0.0);
    }
    return 100.0 * share;
}

PixelInCurrent planePixelInCurrent(cv::Point2d baselinePx, const PlaneFrame& plane, const RigidTransform& toBaseline,
                                   const cv::Matx33d& k) {
    const std::optional<cv::Vec3d> onPlane = plane.rayHit(k.inv() * cv::Vec3d(baselinePx.x, baselinePx.y, 1.0));
    if (!onPlane) return {{kNaN, kNaN}, kNaN};  // the pixel looks past the plane: nowhere on it
    const cv::Vec3d moved = toBaseline.rotation.t() * (*onPlane - toBaseline.translation);
    const cv::Vec3d seen = k * moved;
    return {{seen[0] / seen[2], seen[1] / seen[2]}, moved[2]};
}

}  // namespace icewatch::volume
