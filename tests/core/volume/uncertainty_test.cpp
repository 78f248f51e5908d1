#include "core/volume/uncertainty.hpp"

#include <cmath>

#include <gtest/gtest.h>

namespace icewatch::volume {
namespace {

// A flat 20 x 10 grid of 2 mm cells, all of it possible ice, 1 mm thick everywhere.
ThicknessMap flatMap() {
    ThicknessMap map;
    map.grid = GridSpec{0, 0, 2, 2, 20, 10};
    map.thickness = cv::Mat(10, 20, CV_64F, cv::Scalar(1.0));
    map.baselineHeight = cv::Mat(10, 20, CV_64F, cv::Scalar(0.0));
    map.inside = cv::Mat(10, 20, CV_8U, cv::Scalar(1));
    map.onIce = cv::Mat(10, 20, CV_8U, cv::Scalar(1));
    map.insideNodes = map.iceNodes = 200;
    return map;
}

TEST(VolumeUncertainty, ThePushCountsWithWhatIsNotKnownOfIt) {
    const ThicknessMap map = flatMap();
    PlaneFrame plane;
    plane.origin = {0, 0, 1000};
    const ViewGeometry view{1000.0, 60.0, 1000.0};  // ΔZ of 1 px: 1000² / (1000 · 60) mm
    const double depthPerPx = 1000.0 * 1000.0 / (1000.0 * 60.0);
    const double area = 200 * 4.0;
    MatcherPush push;
    push.meanPx = 0.01;
    push.sigmaPx = 0.0;
    const Parameters p;
    EXPECT_NEAR(volumeUncertainty(map, plane, {}, push, view, p, 800.0).pushMm3, 0.01 * depthPerPx * area, 1e-9);
    // Measured to ±0.05 px: a push of 0.01 px is known no better than that.
    push.sigmaPx = 0.05;
    EXPECT_NEAR(volumeUncertainty(map, plane, {}, push, view, p, 800.0).pushMm3,
                std::hypot(0.01, 0.05) * depthPerPx * area, 1e-9);
}

}  // namespace
}  // namespace icewatch::volume
