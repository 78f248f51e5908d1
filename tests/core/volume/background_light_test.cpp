#include "core/volume/background_light.hpp"

#include <gtest/gtest.h>

#include "core/synth/texture.hpp"
#include "core/volume/image_motion.hpp"
#include "core/volume/patch_tracker.hpp"
#include "core/volume/texture_tracks.hpp"

namespace icewatch::volume {
namespace {

const cv::Size kSize(320, 200);
const cv::Rect kObject(100, 60, 120, 80);

cv::Mat objectMask() {
    cv::Mat roi(kSize, CV_8U, cv::Scalar(0));
    roi(kObject).setTo(255);
    return roi;
}

// A textured object against a featureless sky (or on a textured table: `table`) seen `shiftX` px to
// the left, the whole scene times `light` and the object (where it appears) times `objectGain` on
// top.
cv::Mat view(double shiftX, double light, double objectGain, bool table = true) {
    cv::Mat image(kSize, CV_32F);
    for (int y = 0; y < kSize.height; ++y)
        for (int x = 0; x < kSize.width; ++x) {
            const double u = x + shiftX;
            const bool onObject = kObject.contains(cv::Point(static_cast<int>(std::floor(u)), y));
            double grey = onObject || table ? 120.0 + 25.0 * synth::fractalNoise(u, y, 9.0, 3, 11) : 200.0;
            if (onObject) grey *= objectGain;
            image.at<float>(y, x) = static_cast<float>(grey * light);
        }
    return image;
}

TEST(BackgroundLight, IsTheBackgroundsChangeNotTheObjects) {
    const cv::Mat roi = objectMask();
    const cv::Rect frame(cv::Point(0, 0), kSize);
    const cv::Mat before = view(0, 1.0, 1.0);
    // Light over the whole scene: the background says so.
    const auto light = backgroundLightRatio(before, view(0, 1.1, 1.0), roi, frame, frame);
    ASSERT_TRUE(light);
    EXPECT_NEAR(*light, 1.1, 1e-4);
    // A white layer on the object alone: the background's light did not change.
    const auto layer = backgroundLightRatio(before, view(0, 1.0, 1.15), roi, frame, frame);
    ASSERT_TRUE(layer);
    EXPECT_NEAR(*layer, 1.0, 1e-4);
}

TEST(BackgroundLight, LeavesOutClippedPixelsAndAnswersNothingWithoutBackground) {
    const cv::Mat roi = objectMask();
    const cv::Rect frame(cv::Point(0, 0), kSize);
    cv::Mat before = view(0, 1.0, 1.0), after = view(0, 1.2, 1.0);
    // The left third of the background white in the current capture (clipped): it says nothing.
    after(cv::Rect(0, 0, 90, kSize.height)).setTo(255.0f);
    const auto light = backgroundLightRatio(before, after, roi, frame, frame);
    ASSERT_TRUE(light);
    EXPECT_NEAR(*light, 1.2, 1e-4);
    // Windows that hold only the object and its margin: no background to ask.
    const cv::Rect tight(kObject.x - 20, kObject.y - 20, kObject.width + 40, kObject.height + 40);
    EXPECT_FALSE(backgroundLightRatio(before, after, roi, tight, frame));
    EXPECT_FALSE(backgroundLightRatio(before, after, roi, frame, tight));
}

struct Capture {
    TrackingImage left, right;
    cv::Mat disparity;
};

constexpr double kDisparity = 12.0;

Capture capture(double light, double objectGain, bool table = true) {
    Capture c;
    c.left = prepareForTracking(view(0, light, objectGain, table));
    c.right = prepareForTracking(view(kDisparity, light, objectGain, table));  // right(x) = left(x + d)
    c.disparity = cv::Mat(kSize, CV_32F, cv::Scalar(kDisparity));
    return c;
}

struct Counts {
    int objectUnchanged = 0, objectChanged = 0, backgroundUnchanged = 0;
};

Counts track(const Capture& before, const Capture& after, std::optional<double> light) {
    const RectifiedCapture b{before.left, before.right, before.disparity};
    const RectifiedCapture a{after.left, after.right, after.disparity};
    TextureTrackOptions options;
    options.stepPx = 10;
    const BaselineSamples samples = baselineSamples(b, objectMask(), options);
    cv::Matx44d q = cv::Matx44d::zeros();  // f = 800 px, baseline 60 mm
    q(0, 0) = q(1, 1) = 1.0;
    q(0, 3) = -kSize.width / 2.0;
    q(1, 3) = -kSize.height / 2.0;
    q(2, 3) = 800.0;
    q(3, 2) = 1.0 / 60.0;
    Counts counts;
    for (const TextureTrack& t : trackTexture(samples, b, a, q, translation({0, 0}), light, options)) {
        if (t.onObject && t.state == TextureTrack::State::Unchanged) ++counts.objectUnchanged;
        if (t.onObject && t.state == TextureTrack::State::Changed) ++counts.objectChanged;
        if (!t.onObject && t.state == TextureTrack::State::Unchanged) ++counts.backgroundUnchanged;
    }
    return counts;
}

TEST(BackgroundLight, AWhiteLayerOverTheWholeObjectIsAChangedLookNotLight) {
    const Capture before = capture(1.0, 1.0);
    const cv::Rect frame(cv::Point(0, 0), kSize);
    // The object 12 % brighter under an unchanged light: against the background's light, every
    // object sample changed its look; the background's did not.
    const Capture layer = capture(1.0, 1.12);
    const auto light = backgroundLightRatio(view(0, 1.0, 1.0), view(0, 1.0, 1.12), objectMask(), frame, frame);
    const Counts c = track(before, layer, light);
    EXPECT_GT(c.objectChanged, 20);
    EXPECT_EQ(c.objectUnchanged, 0);
    EXPECT_GT(c.backgroundUnchanged, 50);
    // Against a featureless sky no background sample is found again, and the median of the
    // object's own samples would take the layer for light; the sky's light does not.
    const Capture skyBefore = capture(1.0, 1.0, false), skyLayer = capture(1.0, 1.12, false);
    const auto skyLight =
        backgroundLightRatio(view(0, 1.0, 1.0, false), view(0, 1.0, 1.12, false), objectMask(), frame, frame);
    ASSERT_TRUE(skyLight);
    EXPECT_NEAR(*skyLight, 1.0, 1e-4);
    const Counts sky = track(skyBefore, skyLayer, skyLight);
    EXPECT_EQ(sky.objectUnchanged, 0);
    EXPECT_GT(sky.objectChanged, 20);
    EXPECT_EQ(sky.backgroundUnchanged, 0);
    EXPECT_GT(track(skyBefore, skyLayer, std::nullopt).objectUnchanged, 20);
    // The same 12 % over the whole scene is light: nothing changed its look.
    const Capture brighter = capture(1.12, 1.0);
    const auto sceneLight = backgroundLightRatio(view(0, 1.0, 1.0), view(0, 1.12, 1.0), objectMask(), frame, frame);
    const Counts l = track(before, brighter, sceneLight);
    EXPECT_EQ(l.objectChanged, 0);
    EXPECT_GT(l.objectUnchanged, 20);
}

TEST(BackgroundLight, ObjectLightNoteSaysWhenTheObjectAloneChangedItsBrightness) {
    std::vector<TextureTrack> tracks(9);
    for (TextureTrack& t : tracks) {
        t.onObject = true;
        t.state = TextureTrack::State::Changed;
        t.brightnessRatio = 1.12;
    }
    EXPECT_NE(objectLightNote(tracks, 1.0, 0.04).find("layer of ice over all of it"), std::string::npos);
    EXPECT_TRUE(objectLightNote(tracks, 1.11, 0.04).empty());
    EXPECT_TRUE(objectLightNote(tracks, std::nullopt, 0.04).empty());
}

}  // namespace
}  // namespace icewatch::volume
