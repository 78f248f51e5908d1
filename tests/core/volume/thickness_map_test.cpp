#include "core/volume/thickness_map.hpp"

#include <optional>
#include <string>

#include <gtest/gtest.h>

#include "tests/core/volume/test_planes.hpp"

namespace icewatch::volume {
namespace {

cv::Mat rectangleRegion(int x0, int y0, int x1, int y1) {
    cv::Mat roi = cv::Mat::zeros(480, 640, CV_8U);
    roi(cv::Rect(cv::Point(x0, y0), cv::Point(x1 + 1, y1 + 1))).setTo(255);
    return roi;
}

TEST(OutlineGrid, AnOutlineFacingTheCameraSpansItsOwnExtentOnThePlane) {
    PlaneFrame wall;  // 1 m ahead, facing the camera: a pixel is a millimetre on it
    wall.origin = {0, 0, 1000};
    wall.normal = {0, 0, -1};
    wall.axisU = {1, 0, 0};
    wall.axisV = wall.normal.cross(wall.axisU);
    const OutlineGrid region = outlineGrid(rectangleRegion(220, 190, 420, 290), wall, test::kCamera, 2.0);
    ASSERT_TRUE(region.grid) << region.problem;
    EXPECT_TRUE(region.problem.empty());
    EXPECT_EQ(region.grid->nu, 101);  // 200 mm at 2 mm
    EXPECT_EQ(region.grid->nv, 51);   // 100 mm
    EXPECT_NEAR(region.grid->u0, -100.0, 1e-9);
    EXPECT_NEAR(region.grid->du, 2.0, 1e-9);
}

TEST(OutlineGrid, AnOutlineOverThePlanesHorizonHasNoGridAndNamesAPixel) {
    const OutlineGrid region = outlineGrid(rectangleRegion(220, 200, 420, 300), test::groundBelowCamera(), test::kCamera, 2.0);
    EXPECT_FALSE(region.grid);
    EXPECT_NE(region.problem.find("looks past the region's plane"), std::string::npos) << region.problem;
    EXPECT_NE(region.problem.find("outline's pixel ("), std::string::npos) << region.problem;
}

TEST(OutlineGrid, AnOutlineJustUnderTheHorizonReachesTooFarForAGrid) {
    // Row 241 meets the ground 100 m ahead: kilometres of grid at 1 mm.
    const OutlineGrid far = outlineGrid(rectangleRegion(220, 241, 420, 300), test::groundBelowCamera(), test::kCamera, 1.0);
    EXPECT_FALSE(far.grid);
    EXPECT_NE(far.problem.find("nodes is too many"), std::string::npos) << far.problem;
    // Well under it (0.6 to 1.7 m ahead) the ground is gridded.
    const OutlineGrid near = outlineGrid(rectangleRegion(220, 300, 420, 400), test::groundBelowCamera(), test::kCamera, 10.0);
    ASSERT_TRUE(near.grid) << near.problem;
    EXPECT_GT(near.grid->nv, 100);
}

}  // namespace
}  // namespace icewatch::volume
