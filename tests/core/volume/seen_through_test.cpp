#include "core/volume/seen_through.hpp"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "core/volume/thickness_map.hpp"
#include "core/volume/uncertainty.hpp"

namespace icewatch::volume {
namespace {

// An object filling `square` of a side x side image.
cv::Mat squareObject(int side, const cv::Rect& square) {
    cv::Mat object(side, side, CV_8U, cv::Scalar(0));
    object(square).setTo(255);
    return object;
}

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
    const cv::Mat object = squareObject(80, {10, 10, 60, 60});
    const std::vector<TextureTrack> tracks = {sample(20, 45, TextureTrack::State::Unchanged),
                                              sample(60, 45, TextureTrack::State::Changed),
                                              sample(40, 15, TextureTrack::State::Untracked)};
    const cv::Mat seen = seenThroughPixels(object, tracks, 40);
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
    EXPECT_EQ(cv::countNonZero(seenThroughPixels(object, unchanged, 40)), 0);
    // Unless that texture, as a whole, brightened against the light: a thin layer over all of the
    // object changed it too, only less. What was never found again still says nothing.
    const cv::Mat layered = seenThroughPixels(object, unchanged, 40, true);
    EXPECT_EQ(layered.at<std::uint8_t>(45, 15), 255);
    EXPECT_EQ(layered.at<std::uint8_t>(45, 65), 255);
    EXPECT_EQ(layered.at<std::uint8_t>(45, 75), 0) << "outside the object";
    const std::vector<TextureTrack> hidden = {sample(20, 45, TextureTrack::State::Untracked)};
    EXPECT_EQ(cv::countNonZero(seenThroughPixels(object, hidden, 40, true)), 0);
}

TextureTrack glimpse(int x, int y, bool lookChanged) {
    TextureTrack t = sample(x, y, TextureTrack::State::Untracked);
    t.glimpsed = true;
    t.glimpsedLookChanged = lookChanged;
    return t;
}

// A 5 x 5 grid of samples 10 px apart over an object: texture glimpsed with its look changed but
// left unmeasured (under a clear layer, refraction shifts it otherwise in each eye) says that
// the ice over it may be seen through, unless clean texture lies beside it (a patch half under an
// edge of opaque ice is glimpsed too); a glimpse whose look did not change says nothing.
TEST(SeenThrough, AGlimpseInsideTheIceSaysGlimpsedThrough) {
    const cv::Mat object = squareObject(70, {5, 5, 60, 60});
    std::vector<TextureTrack> tracks;
    for (int y = 15; y <= 55; y += 10)
        for (int x = 15; x <= 55; x += 10) tracks.push_back(glimpse(x, y, true));
    const cv::Mat all = seenThroughPixels(object, tracks, 10);
    EXPECT_EQ(all.at<std::uint8_t>(35, 35), kGlimpsedThrough);
    EXPECT_EQ(all.at<std::uint8_t>(8, 8), kGlimpsedThrough) << "every pixel of the object";
    EXPECT_EQ(all.at<std::uint8_t>(2, 2), 0) << "outside the object";
    // Clean texture at the left column: the glimpses beside it say nothing; those further in do.
    for (TextureTrack& t : tracks)
        if (t.pixel.x == 15) t.state = TextureTrack::State::Unchanged;
    const cv::Mat edged = seenThroughPixels(object, tracks, 10);
    EXPECT_EQ(edged.at<std::uint8_t>(35, 25), 0) << "beside clean texture";
    EXPECT_EQ(edged.at<std::uint8_t>(35, 45), kGlimpsedThrough);
    // A measured track with a changed look says seen through, and wins its own cell.
    tracks[12].state = TextureTrack::State::Changed;  // (35, 35)
    EXPECT_EQ(seenThroughPixels(object, tracks, 10).at<std::uint8_t>(35, 35), kSeenThrough);
    // A glimpse whose look did not change is no sign of a layer.
    for (TextureTrack& t : tracks) t.glimpsedLookChanged = false;
    tracks[12].state = TextureTrack::State::Untracked;
    EXPECT_EQ(cv::countNonZero(seenThroughPixels(object, tracks, 10)), 0);
    // Unless the object's clean texture as a whole changed against the light (a layer over all).
    EXPECT_EQ(seenThroughPixels(object, tracks, 10, true).at<std::uint8_t>(35, 45), kSeenThrough);
}

// A grid of 2 mm cells, 1 mm read everywhere, a third of it seen through.
ThicknessMap seenThroughMap() {
    ThicknessMap map;
    map.grid = GridSpec{0, 0, 2, 2, 30, 10};
    map.thickness = cv::Mat(10, 30, CV_64F, cv::Scalar(1.0));
    map.seenThrough = cv::Mat(10, 30, CV_8U, cv::Scalar(0));
    map.seenThrough(cv::Rect(0, 0, 10, 10)).setTo(kSeenThrough);
    return map;
}

// Glimpsed ice is summed apart: its estimate is what was read, and the uncertainty reaches
// refraction's full factor from there.
TEST(SeenThrough, IceGlimpsedThroughWidensTheUncertaintyButNotTheEstimate) {
    ThicknessMap map = seenThroughMap();
    map.seenThrough(cv::Rect(10, 0, 10, 10)).setTo(kGlimpsedThrough);
    const SeenThroughIce seen = seenThroughIce(map);
    EXPECT_NEAR(seen.readMm3, 400.0, 1e-9);
    EXPECT_NEAR(seen.glimpsedReadMm3, 400.0, 1e-9);
    EXPECT_EQ(seen.glimpsedNodes, 100);
    const SeenThroughIce seenAlone{400.0, 100};
    EXPECT_EQ(seenThroughShareMm3(seen), seenThroughShareMm3(seenAlone));
    EXPECT_NEAR(seenThroughSigmaMm3(seen), 2.0 * seenThroughSigmaMm3(seenAlone), 1e-9);
    // Read as it is, 2 σ reach what refraction may hide.
    const SeenThroughIce glimpsedAlone{0.0, 0, 400.0, 100};
    EXPECT_GE(2.0 * seenThroughSigmaMm3(glimpsedAlone), (kSeenThroughFactor - 1.0) * 400.0 - 1e-9);
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
