#include "core/volume/outlier_filter.hpp"

#include <gtest/gtest.h>

#include "core/common/error.hpp"

namespace icewatch::volume {
namespace {

TEST(OutlierFilter, RemovesPlantedOutliersAndKeepsTheSurface) {
    std::vector<cv::Point3d> points;
    cv::RNG rng(3);
    for (int y = 0; y < 60; ++y)
        for (int x = 0; x < 60; ++x) points.emplace_back(x, y, 0.05 * x + rng.gaussian(0.2));
    std::vector<std::size_t> planted;
    for (int k = 0; k < 30; ++k) {
        const std::size_t i = static_cast<std::size_t>(rng.uniform(0, static_cast<int>(points.size())));
        points[i].z += (k % 2 ? 8.0 : -8.0);
        planted.push_back(i);
    }
    const auto keep = knnKeepMask(points, 8, 2.0);
    for (std::size_t i : planted) EXPECT_EQ(keep[i], 0) << "planted outlier " << i << " kept";
    std::size_t kept = 0;
    for (auto k : keep) kept += k;
    // θ = 2 trims the far tails of honest noise too, but only a small share.
    EXPECT_GT(kept, points.size() * 85 / 100);
}

TEST(OutlierFilter, RejectsBadParameters) {
    EXPECT_THROW(knnKeepMask({}, 1, 2.0), InvalidInput);
    EXPECT_THROW(knnKeepMask({}, 8, 0.0), InvalidInput);
}

}  // namespace
}  // namespace icewatch::volume
