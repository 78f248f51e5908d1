#include "core/volume/seen_through.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "core/volume/thickness_map.hpp"
#include "core/volume/uncertainty.hpp"

namespace icewatch::volume {
namespace {

TextureTrack sample(int x, int y, TextureTrack::State state) {
    TextureTrack t;
    t.pixel = {x, y};
    t.onObject = true;
    t.state = state;
    return t;
}

// Three samples across a 60 x 60 object: clean surface on the left, texture found again with a
// changed look (seen through ice) on the right, texture lost (opaque ice) at the top.
TEST(SeenThrough, EveryPixelTakesTheWordOfItsNearestSample) {
    cv::Mat object(80, 80, CV_8U, cv::Scalar(0));
    object(cv::Rect(10, 10, 60, 60)).setTo(255);
    const std::vector<TextureTrack> tracks = {sample(20, 45, TextureTrack::State::Unchanged),
                                              sample(60, 45, TextureTrack::State::Changed),
                                              sample(40, 15, TextureTrack::State::Untracked)};
    const cv::Mat seen = seenThroughPixels(object, tracks);
    EXPECT_EQ(seen.at<std::uint8_t>(45, 65), 255) << "next to the texture seen through the ice";
    EXPECT_EQ(seen.at<std::uint8_t>(60, 50), 255);
    EXPECT_EQ(seen.at<std::uint8_t>(45, 15), 0) << "next to clean surface";
    EXPECT_EQ(seen.at<std::uint8_t>(12, 40), 0) << "next to texture the ice hid";
    EXPECT_EQ(seen.at<std::uint8_t>(45, 75), 0) << "outside the object";
    // Texture found again with its look unchanged is not taken for seen through, whether it moved
    // with the object or rose (an edge of opaque ice entered its patch, a motion the model does
    // not quite fit): nothing marked.
    const std::vector<TextureTrack> unchanged = {sample(20, 45, TextureTrack::State::Unchanged),
                                                 sample(60, 45, TextureTrack::State::Unchanged),
                                                 sample(40, 15, TextureTrack::State::Untracked)};
    EXPECT_EQ(cv::countNonZero(seenThroughPixels(object, unchanged)), 0);
    // Unless that texture, as a whole, brightened against the light: a thin layer over all of the
    // object changed it too, only less. What was never found again still says nothing.
    const cv::Mat layered = seenThroughPixels(object, unchanged, true);
    EXPECT_EQ(layered.at<std::uint8_t>(45, 15), 255);
    EXPECT_EQ(layered.at<std::uint8_t>(45, 65), 255);
    EXPECT_EQ(layered.at<std::uint8_t>(45, 75), 0) << "outside the object";
    const std::vector<TextureTrack> hidden = {sample(20, 45, TextureTrack::State::Untracked)};
    EXPECT_EQ(cv::countNonZero(seenThroughPixels(object, hidden, true)), 0);
}

// A grid of 2 mm cells, 1 mm read everywhere, a third of it seen through.
ThicknessMap seenThroughMap() {
    ThicknessMap map;
    map.grid = GridSpec{0, 0, 2, 2, 30, 10};
    map.thickness = cv::Mat(10, 30, CV_64F, cv::Scalar(1.0));
    map.seenThrough = cv::Mat(10, 30, CV_8U, cv::Scalar(0));
    map.seenThrough(cv::Rect(0, 0, 10, 10)).setTo(255);
    return map;
}

TEST(SeenThrough, TheIceReadWhereTheTextureWasSeenThroughIsSummedWithItsSign) {
    ThicknessMap map = seenThroughMap();
    EXPECT_NEAR(seenThroughIce(map).readMm3, 100 * 4.0, 1e-9);
    EXPECT_EQ(seenThroughIce(map).nodes, 100);
    // Clean surface read with noise about nothing cancels; a net negative is no ice.
    map.thickness(cv::Rect(0, 0, 5, 10)).setTo(-1.0);
    EXPECT_NEAR(seenThroughIce(map).readMm3, 0.0, 1e-9);
    map.thickness(cv::Rect(0, 0, 6, 10)).setTo(-1.0);
    EXPECT_EQ(seenThroughIce(map).readMm3, 0.0);
    EXPECT_EQ(seenThroughIce(ThicknessMap{}).readMm3, 0.0);
}

// Refraction raises the surface under clear ice by (1 − 1/n) of the ice; a layer that shows its
// own surface, by all of it. The estimate and its k = 2 uncertainty hold both, and more.
TEST(SeenThrough, TheEstimateCoversBothWhatWasReadAndRefractionsFullFactor) {
    const SeenThroughIce seen{1000.0, 10};
    const double estimate = seen.readMm3 + seenThroughShareMm3(seen);
    const double uncertainty = 2.0 * seenThroughSigmaMm3(seen);
    EXPECT_NEAR(kSeenThroughFactor, 1.0 / (1.0 - 1.0 / 1.31), 1e-12);
    EXPECT_LE(std::abs(estimate - seen.readMm3), uncertainty);
    EXPECT_LE(std::abs(estimate - kSeenThroughFactor * seen.readMm3), uncertainty);
    // With room for the read's own error at either end: a painted layer read 30 % over its truth.
    EXPECT_LE(std::abs(estimate - seen.readMm3 / 1.3), uncertainty);
    EXPECT_EQ(seenThroughShareMm3(SeenThroughIce{}), 0.0);
    // In the budget.
    ThicknessMap map = seenThroughMap();
    map.baselineHeight = cv::Mat(10, 30, CV_64F, cv::Scalar(0.0));
    map.inside = map.onIce = cv::Mat(10, 30, CV_8U, cv::Scalar(255));
    map.insideNodes = map.iceNodes = 300;
    PlaneFrame plane;
    plane.origin = {0, 0, 1000};
    const UncertaintyBudget b =
        volumeUncertainty(map, plane, {}, {}, {1000.0, 60.0, 1000.0}, Parameters{}, 1200.0, seenThroughIce(map));
    EXPECT_NEAR(b.seenThroughMm3, seenThroughSigmaMm3(seenThroughIce(map)), 1e-9);
    EXPECT_GT(b.seenThroughMm3, 0.0);
}

}  // namespace
}  // namespace icewatch::volume
