#include "core/volume/outlier_filter.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

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
    EXPECT_THROW(knnKeepMaskReference({}, 1, 2.0), InvalidInput);
    std::vector<cv::Point3d> points(20, cv::Point3d(1, 2, 3));
    points[7].y = std::numeric_limits<double>::quiet_NaN();
    EXPECT_THROW(knnKeepMask(points, 8, 2.0), InvalidInput);
}

// Heights with a share of strays, so that both answers have points to drop.
void addHeights(std::vector<cv::Point3d>& points, cv::RNG& rng) {
    for (auto& p : points) p.z = 0.02 * p.x + rng.gaussian(0.3) + (rng.uniform(0, 20) == 0 ? 5.0 : 0.0);
}

void expectSameAsReference(const std::vector<cv::Point3d>& points, const std::string& what) {
    for (int k : {2, 8, 15}) {
        const auto fast = knnKeepMask(points, k, 2.0);
        const auto reference = knnKeepMaskReference(points, k, 2.0);
        ASSERT_EQ(fast.size(), reference.size());
        std::size_t differ = 0, dropped = 0;
        for (std::size_t i = 0; i < fast.size(); ++i) {
            differ += fast[i] != reference[i];
            dropped += reference[i] == 0;
        }
        EXPECT_EQ(differ, 0u) << what << ", k = " << k;
        EXPECT_GT(dropped, 0u) << what << ", k = " << k << ": a comparison with nothing dropped shows little";
    }
}

TEST(OutlierFilter, BucketSearchAgreesWithTheBruteForceReference) {
    cv::RNG rng(11);
    std::vector<cv::Point3d> uniform(1500);
    for (auto& p : uniform) p = {rng.uniform(-40.0, 60.0), rng.uniform(5.0, 35.0), 0};
    addHeights(uniform, rng);
    expectSameAsReference(uniform, "uniform");

    // A pixel lattice: distances tie everywhere, so the lower index must win in both.
    std::vector<cv::Point3d> lattice;
    for (int y = 0; y < 31; ++y)
        for (int x = 0; x < 47; ++x) lattice.emplace_back(x, y, 0);
    addHeights(lattice, rng);
    expectSameAsReference(lattice, "lattice");

    // Duplicates, two clusters far apart (most buckets empty), and a line (a box of no area).
    std::vector<cv::Point3d> odd;
    for (int i = 0; i < 600; ++i) {
        const double cx = i % 2 ? 0.0 : 5000.0;
        odd.emplace_back(cx + std::round(rng.uniform(0.0, 10.0)), std::round(rng.uniform(0.0, 10.0)), 0);
    }
    addHeights(odd, rng);
    expectSameAsReference(odd, "clusters with duplicates");
    std::vector<cv::Point3d> line(400);
    for (auto& p : line) p = {rng.uniform(0.0, 100.0), 3.0, 0};
    addHeights(line, rng);
    expectSameAsReference(line, "line");
}

TEST(OutlierFilter, KeepsEveryPointOfASmallCloud) {
    std::vector<cv::Point3d> points = {{0, 0, 0}, {1, 0, 0}, {0, 1, 100}};
    EXPECT_EQ(knnKeepMask(points, 3, 2.0), std::vector<std::uint8_t>(3, 1));
}

}  // namespace
}  // namespace icewatch::volume
