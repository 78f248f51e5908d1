#include "core/volume/height_grid.hpp"

#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <string>

#include <gtest/gtest.h>

#include "core/common/error.hpp"
#include "tests/core/volume/test_planes.hpp"

namespace icewatch::volume {
namespace {

constexpr double kPi = 3.14159265358979323846;

// A scattered cloud on a slightly jittered pixel lattice, as a camera would give it.
cv::Mat latticeCloud(int n, double extentMm, const std::function<double(double, double)>& height) {
    cv::Mat cloud(n, n, CV_64FC3);
    cv::RNG rng(7);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const double u = -extentMm + 2 * extentMm * x / (n - 1) + rng.uniform(-0.1, 0.1);
            const double v = -extentMm + 2 * extentMm * y / (n - 1) + rng.uniform(-0.1, 0.1);
            cloud.at<cv::Vec3d>(y, x) = {u, v, height(u, v)};
        }
    return cloud;
}

TEST(HeightGrid, ParaboloidCapBothMethods) {
    const double radius = 40, heightMm = 10;
    auto cap = [&](double u, double v) { return std::max(0.0, heightMm * (1 - (u * u + v * v) / (radius * radius))); };
    const cv::Mat cloud = latticeCloud(201, 50, cap);
    const GridSpec grid = makeGrid(-49, 49, -49, 49, 0.5);
    const cv::Mat values = interpolateLattice(cloud, grid);
    const double exact = kPi * radius * radius * heightMm / 2;  // paraboloid cap: half its cylinder
    EXPECT_NEAR(integrate(values, grid, Integration::Trapz), exact, 0.005 * exact);
    EXPECT_NEAR(integrate(values, grid, Integration::Sum), exact, 0.005 * exact);
}

TEST(HeightGrid, BoxBothMethods) {
    // Edges half-way between nodes: both rules then integrate the box exactly (41 × 31 mm × 30 mm).
    auto box = [](double u, double v) { return (std::abs(u) < 20.5 && std::abs(v) < 15.5) ? 30.0 : 0.0; };
    cv::Mat values(81, 101, CV_64F);
    const GridSpec grid = makeGrid(-50, 50, -40, 40, 1.0);
    for (int j = 0; j < grid.nv; ++j)
        for (int i = 0; i < grid.nu; ++i) values.at<double>(j, i) = box(grid.u0 + i * grid.du, grid.v0 + j * grid.dv);
    const double exact = 41.0 * 31.0 * 30.0;
    EXPECT_NEAR(integrate(values, grid, Integration::Trapz), exact, 1e-9);
    EXPECT_NEAR(integrate(values, grid, Integration::Sum), exact, 1e-9);
}

TEST(HeightGrid, GridSpacingFollowsThePaper) {
    const GridSpec grid = makeGrid(0, 10, 0, 4, 3.0);
    EXPECT_EQ(grid.nu, 5);
    EXPECT_EQ(grid.nv, 3);
    EXPECT_DOUBLE_EQ(grid.du, 10.0 / 4);
    EXPECT_DOUBLE_EQ(grid.dv, 4.0 / 2);
}

// An outline whose rays graze the plane puts its extent kilometres off, or at infinity: the grid
// refuses it with the count it would have needed rather than overflowing the cast to int.
TEST(HeightGrid, AGridOfKilometresOrOfNoFiniteExtentIsAnErrorNamingItsSize) {
    try {
        makeGrid(0, 4.8e6, 0, 7.7e5, 1.0);
        FAIL() << "a grid of 4.8 km x 770 m at 1 mm was built";
    } catch (const InvalidInput& e) {
        EXPECT_NE(std::string(e.what()).find("4800001 x 770001 nodes is too many"), std::string::npos) << e.what();
    }
    EXPECT_THROW(makeGrid(0, std::numeric_limits<double>::infinity(), 0, 10, 1.0), InvalidInput);
    EXPECT_THROW(makeGrid(0, 10, 0, std::numeric_limits<double>::quiet_NaN(), 1.0), InvalidInput);
    EXPECT_THROW(makeGrid(0, 10, 0, 10, 0.0), InvalidInput);
    const GridSpec fine = makeGrid(0, 10, 0, 4, 0.5);
    EXPECT_EQ(fine.nu, 21);
    EXPECT_EQ(fine.nv, 9);
}

TEST(PlaneFrame, ARayMeetsThePlaneInFrontOfItsStartOrNowhere) {
    const PlaneFrame ground = test::groundBelowCamera();
    // Looking down 45 degrees: the ground 100 mm ahead.
    const std::optional<cv::Vec3d> ahead = ground.rayHit({0, 1, 1});
    ASSERT_TRUE(ahead);
    EXPECT_NEAR(cv::norm(*ahead - cv::Vec3d(0, 100, 100)), 0.0, 1e-9);
    // From a point 40 mm above the ground, straight down.
    const std::optional<cv::Vec3d> below = ground.rayHit({0, 1, 0}, {5, 60, 700});
    ASSERT_TRUE(below);
    EXPECT_NEAR(cv::norm(*below - cv::Vec3d(5, 100, 700)), 0.0, 1e-9);
    EXPECT_FALSE(ground.rayHit({0, 0, 1}));   // along the horizon: never
    EXPECT_FALSE(ground.rayHit({0, -1, 1}));  // above it: the plane is behind
}

TEST(HeightGrid, TheReasonForNoGridIsGivenInWordsAndMakeGridThrowsIt) {
    const GridOrProblem fine = gridOver(0, 10, 0, 4, 0.5);
    ASSERT_TRUE(fine.grid);
    EXPECT_TRUE(fine.problem.empty());
    EXPECT_EQ(fine.grid->nu, 21);
    const GridOrProblem huge = gridOver(0, 4.8e6, 0, 7.7e5, 1.0);
    EXPECT_FALSE(huge.grid);
    EXPECT_NE(huge.problem.find("4800001 x 770001 nodes is too many"), std::string::npos) << huge.problem;
    EXPECT_FALSE(gridOver(0, 10, 0, 10, 0.0).grid);
    EXPECT_NE(gridOver(0, 10, 0, 10, 0.0).problem.find("positive size"), std::string::npos);
    try {
        makeGrid(0, 10, 0, 10, -1.0);
        FAIL() << "a grid with a negative cell was built";
    } catch (const InvalidInput& e) {
        EXPECT_EQ(std::string(e.what()), gridOver(0, 10, 0, 10, -1.0).problem);
    }
}

TEST(HeightGrid, LinearInterpolationIsExactOnAPlaneAndLeavesHolesOpen) {
    cv::Mat cloud = latticeCloud(41, 20, [](double u, double v) { return 2 + 0.3 * u - 0.2 * v; });
    for (int y = 15; y < 25; ++y)
        for (int x = 15; x < 25; ++x) cloud.at<cv::Vec3d>(y, x)[2] = std::nan("");
    const GridSpec grid = makeGrid(-19, 19, -19, 19, 0.5);
    cv::Mat values = interpolateLattice(cloud, grid);
    int covered = 0;
    for (int j = 0; j < grid.nv; ++j)
        for (int i = 0; i < grid.nu; ++i) {
            const double h = values.at<double>(j, i);
            if (std::isnan(h)) continue;
            ++covered;
            EXPECT_NEAR(h, 2 + 0.3 * (grid.u0 + i * grid.du) - 0.2 * (grid.v0 + j * grid.dv), 1e-9);
        }
    EXPECT_TRUE(std::isnan(values.at<double>(grid.nv / 2, grid.nu / 2)));  // the hole stays a hole
    const cv::Mat inside(values.size(), CV_8U, cv::Scalar(255));
    EXPECT_GT(fillFromNearest(values, inside), 0);
    EXPECT_FALSE(std::isnan(values.at<double>(grid.nv / 2, grid.nu / 2)));
    EXPECT_GT(covered, grid.nu * grid.nv / 2);
}

// A block seen from above its centre hides a band of the ground around it: the pixel next to
// the top's edge lands on the ground several millimetres further out. Rows of a lattice: ground
// pixels up to u = 7, a hidden band 7..10, the top (50 mm) from 10 to 20, hidden again 20..23,
// ground from 23.
cv::Mat occludedBlockRows() {
    std::vector<std::pair<double, double>> columns;  // u, h
    for (int i = 0; i <= 7; ++i) columns.emplace_back(i, 0.0);
    for (int i = 10; i <= 20; ++i) columns.emplace_back(i, 50.0);
    for (int i = 23; i <= 30; ++i) columns.emplace_back(i, 0.0);
    cv::Mat cloud(6, static_cast<int>(columns.size()), CV_64FC3);
    for (int y = 0; y < cloud.rows; ++y)
        for (int x = 0; x < cloud.cols; ++x) cloud.at<cv::Vec3d>(y, x) = {columns[x].first, double(y), columns[x].second};
    return cloud;
}

TEST(HeightGrid, OcclusionStepsEndTheNearSurfaceInAWall) {
    const cv::Mat cloud = occludedBlockRows();
    const GridSpec grid = makeGrid(0, 30, 0, 5, 0.25);
    // The top seen at pixels 10 .. 20 ends, on average, half a pixel beyond its last ones: its
    // edges lie anywhere between them and the next pixels, which see the ground. 11 wide.
    const double block = 50.0 * 11.0 * 5.0;
    // Bridged, the ramps span the hidden bands from the top's last pixels (10 and 20).
    const double bridgedBlock = 50.0 * 10.0 * 5.0, ramps = 2 * 0.5 * 50.0 * 3.0 * 5.0;
    const cv::Mat bridged = interpolateLattice(cloud, grid);
    EXPECT_NEAR(integrate(bridged, grid, Integration::Trapz), bridgedBlock + ramps, 0.01 * bridgedBlock);
    const cv::Mat walled = interpolateLattice(cloud, grid, {4.0, 8.0});
    // Each wall falls between two nodes here (9.5 is ground, 9.75 the top): the trapezoids across
    // them count half a node's width of it short, 1.1 % at each edge.
    EXPECT_NEAR(integrate(walled, grid, Integration::Trapz), block, 0.025 * block);
    EXPECT_DOUBLE_EQ(walled.at<double>(2, 4 * 8), 0.0);   // u = 8, inside the hidden band: ground
    EXPECT_DOUBLE_EQ(walled.at<double>(2, 4 * 9 + 3), 50.0);  // u = 9.75, within half a pixel of the top
    EXPECT_DOUBLE_EQ(walled.at<double>(2, 4 * 9 + 1), 0.0);   // u = 9.25, beyond it
    EXPECT_DOUBLE_EQ(walled.at<double>(2, 4 * 15), 50.0);  // the top is untouched
}

// The same block seen from an eye 45° off its normal, up the u axis: the band it hides lies
// behind the top's far edge (20 .. 70 at 50 mm) and slopes at 1 along the line of sight, far from
// the plane's normal. Bridged, it counts a ramp as large as the block.
TEST(HeightGrid, SeenAtAnAngleTheHiddenBandLiesAlongTheLineOfSight) {
    std::vector<std::pair<double, double>> columns;  // u, h
    for (int i = 0; i <= 10; ++i) columns.emplace_back(i, 0.0);
    for (int i = 10; i <= 20; ++i) columns.emplace_back(i + 0.01, 50.0);
    for (int i = 70; i <= 80; ++i) columns.emplace_back(i, 0.0);
    cv::Mat cloud(6, static_cast<int>(columns.size()), CV_64FC3);
    for (int y = 0; y < cloud.rows; ++y)
        for (int x = 0; x < cloud.cols; ++x) cloud.at<cv::Vec3d>(y, x) = {columns[x].first, double(y), columns[x].second};
    const GridSpec grid = makeGrid(0, 80, 0, 5, 0.25);
    // The top seen from 10.01 to 20.01: on its near side the ground's last pixel is beside it, on
    // its far side it ends half a pixel beyond its last one.
    const double block = 50.0 * 10.5 * 5.0;
    // The eye 800 mm away along (-1, 0, 1) / sqrt(2) from the hidden band's middle, over the plane.
    const cv::Vec3d eye = cv::Vec3d(45, 2.5, 25) + 800.0 * cv::Vec3d(-1, 0, 1) / std::sqrt(2.0);
    const cv::Mat normalOnly = interpolateLattice(cloud, grid, {4.0, 8.0});
    EXPECT_GT(integrate(normalOnly, grid, Integration::Trapz), 1.8 * block);
    const cv::Mat seen = interpolateLattice(cloud, grid, {4.0, 8.0, true, eye});
    EXPECT_NEAR(integrate(seen, grid, Integration::Trapz), block, 0.05 * block);
    EXPECT_DOUBLE_EQ(seen.at<double>(2, 4 * 40), 0.0);  // u = 40, hidden behind the top: ground
    // Facing the camera the eye adds nothing to the normal's rule.
    const cv::Mat facing = interpolateLattice(occludedBlockRows(), makeGrid(0, 30, 0, 5, 0.25), {4.0, 8.0, true, {15, 2.5, 800}});
    const cv::Mat normal = interpolateLattice(occludedBlockRows(), makeGrid(0, 30, 0, 5, 0.25), {4.0, 8.0});
    EXPECT_EQ(cv::norm(facing, normal, cv::NORM_INF), 0.0);
}

TEST(HeightGrid, SmallOrGentleRisesAreNotSteps) {
    // A 5 mm step (below step_min) and a 45° flank keep their linear interpolation.
    cv::Mat cloud(4, 3, CV_64FC3);
    for (int y = 0; y < 4; ++y) {
        cloud.at<cv::Vec3d>(y, 0) = {0.0, double(y), 0.0};
        cloud.at<cv::Vec3d>(y, 1) = {1.0, double(y), 5.0};
        cloud.at<cv::Vec3d>(y, 2) = {21.0, double(y), 25.0};
    }
    const GridSpec grid = makeGrid(0, 21, 0, 3, 0.5);
    const cv::Mat plain = interpolateLattice(cloud, grid);
    const cv::Mat stepped = interpolateLattice(cloud, grid, {4.0, 8.0});
    for (int j = 0; j < grid.nv; ++j)
        for (int i = 0; i < grid.nu; ++i) EXPECT_DOUBLE_EQ(plain.at<double>(j, i), stepped.at<double>(j, i));
}

TEST(HeightGrid, PlaneFitNormalFacesTheCamera) {
    std::vector<cv::Vec3d> points;
    for (int i = 0; i < 100; ++i) points.emplace_back(i % 10, i / 10, 800 + 0.1 * (i % 10));
    const PlaneFrame frame = fitPlane(points);
    EXPECT_LT(frame.normal[2], -0.99);
    EXPECT_NEAR(frame.toPlane(points[55]).z, 0.0, 1e-9);
}

}  // namespace
}  // namespace icewatch::volume
