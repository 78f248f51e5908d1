#include "core/volume/patch_tracker.hpp"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "core/synth/texture.hpp"

namespace icewatch::volume {
namespace {

// A weakly textured surface like the blade's composite (a few grey levels of smooth texture on a
// mid grey), seen shifted by `shift` pixels, times `gain`, blended towards white by `whiten`, with
// Gaussian noise of `noise` grey levels. Each pixel averages 4x4 samples of the continuous
// texture, as a sensor's pixel integrates light, so the shift is exact for the pixels too.
// `contrast`: the texture's amplitude in grey levels; `shading`: a change of the gain across the
// image, per 100 px in x (a surface turning against the light).
cv::Mat sensorView(cv::Size size, cv::Point2d shift, double gain, double whiten, double noise, std::uint32_t seed,
                   double contrast = 8.0, double shading = 0.0, double featurePx = 8.0) {
    constexpr int kSamples = 4;
    cv::Mat image(size, CV_32F);
    std::mt19937 random(seed);
    std::normal_distribution<double> gauss(0.0, 1.0);
    for (int y = 0; y < size.height; ++y)
        for (int x = 0; x < size.width; ++x) {
            double albedo = 0;
            for (int j = 0; j < kSamples; ++j)
                for (int i = 0; i < kSamples; ++i) {
                    const double u = x + (i + 0.5) / kSamples - 0.5 - shift.x, v = y + (j + 0.5) / kSamples - 0.5 - shift.y;
                    albedo += 150.0 + contrast * synth::fractalNoise(u, v, featurePx, 3, 7);
                }
            albedo /= kSamples * kSamples;
            const double localGain = gain * (1.0 + shading * (x - size.width / 2.0) / 100.0);
            const double seen = localGain * albedo * (1.0 - whiten) + whiten * 240.0;
            image.at<float>(y, x) = static_cast<float>(seen + noise * gauss(random));
        }
    return image;
}

// The same, as the trackers read it.
TrackingImage texturedView(cv::Size size, cv::Point2d shift, double gain, double whiten, double noise, std::uint32_t seed,
                           double contrast = 8.0, double shading = 0.0, double featurePx = 8.0) {
    return prepareForTracking(sensorView(size, shift, gain, whiten, noise, seed, contrast, shading, featurePx));
}

struct Bias {
    double meanError = 0;
    double meanOffset = 0;
    int found = 0;
};

Bias trackGrid(const TrackingImage& from, const TrackingImage& to, cv::Point2d truth) {
    Bias b;
    for (int y = 30; y < from.grey.rows - 30; y += 25)
        for (int x = 30; x < from.grey.cols - 30; x += 25) {
            const PatchTrack t = trackPatch(from, to, {x, y}, {0, 0});
            if (!t.found) continue;
            ++b.found;
            b.meanError += t.shift.x - truth.x;
            b.meanOffset += t.offset;
        }
    if (b.found > 0) {
        b.meanError /= b.found;
        b.meanOffset /= b.found;
    }
    return b;
}

TEST(PatchTracker, RecoversSubpixelShiftsWithoutBias) {
    const cv::Size size(400, 300);
    const TrackingImage from = texturedView(size, {0, 0}, 1.0, 0.0, 0.4, 1);
    for (const double fraction : {0.1, 0.25, 0.4, 0.5, 0.7, 0.9}) {
        const cv::Point2d truth(2.0 + fraction, -1.0 + 0.5 * fraction);
        const TrackingImage to = texturedView(size, truth, 1.0, 0.0, 0.4, 2);
        const Bias b = trackGrid(from, to, truth);
        EXPECT_GT(b.found, 100) << fraction;
        EXPECT_LT(std::abs(b.meanError), 0.01) << "fraction " << fraction;
    }
}

// Every patch of a capture shares the fraction of the object's shift, so an interpolator whose
// error depends on that fraction biases them all alike and the bias does not average out: on the
// weak texture, without noise, it must be far below the tracker's noise.
TEST(PatchTracker, NoBiasAtAnyFractionOfAPixel) {
    const cv::Size size(300, 220);
    const TrackingImage from = texturedView(size, {0, 0}, 1.0, 0.0, 0.0, 1, 3.0);
    for (const double fraction : {0.1, 0.25, 0.4, 0.57, 0.71, 0.9}) {
        const cv::Point2d truth(fraction, 1.0 + 0.5 * fraction);
        const Bias b = trackGrid(from, texturedView(size, truth, 1.0, 0.0, 0.0, 2, 3.0), truth);
        EXPECT_GT(b.found, 50) << fraction;
        EXPECT_LT(std::abs(b.meanError), 0.0015) << "fraction " << fraction;
    }
}

// A texture finer than the composite's (features of 3 px, near what the sensor resolves): the
// spline works closer to Nyquist there, and refined on the pixel grid alone its bias reached
// 0.0027 px at some fractions; with the half-pixel grid beside it, under 0.0007 px.
TEST(PatchTracker, NoBiasOnAFineTexture) {
    const cv::Size size(300, 220);
    const TrackingImage from = texturedView(size, {0, 0}, 1.0, 0.0, 0.0, 1, 3.0, 0.0, 3.0);
    for (const double fraction : {0.1, 0.25, 0.4, 0.57, 0.71, 0.9}) {
        const cv::Point2d truth(fraction, 1.0 + 0.5 * fraction);
        const Bias b = trackGrid(from, texturedView(size, truth, 1.0, 0.0, 0.0, 2, 3.0, 0.0, 3.0), truth);
        EXPECT_GT(b.found, 50) << fraction;
        EXPECT_LT(std::abs(b.meanError), 0.0015) << "fraction " << fraction;
    }
}

// A surface that turns against the light changes its shading across a patch; a gain that is only
// constant over the patch would take the ramp for a shift.
TEST(PatchTracker, AShadingRampAcrossThePatchMovesNoShift) {
    const cv::Size size(300, 220);
    const TrackingImage from = texturedView(size, {0, 0}, 1.0, 0.0, 0.0, 1, 3.0);
    const cv::Point2d truth(0.3, 0.2);
    const Bias b = trackGrid(from, texturedView(size, truth, 1.0, 0.0, 0.0, 2, 3.0, 0.02), truth);
    EXPECT_GT(b.found, 50);
    EXPECT_LT(std::abs(b.meanError), 0.0015);
}

TEST(PatchTracker, ALightChangeMovesNeitherTheShiftNorTheOffset) {
    const cv::Size size(400, 300);
    const TrackingImage from = texturedView(size, {0, 0}, 1.0, 0.0, 0.4, 3);
    const cv::Point2d truth(1.3, 0.6);
    const TrackingImage to = texturedView(size, truth, 0.85, 0.0, 0.4, 4);
    const Bias b = trackGrid(from, to, truth);
    EXPECT_GT(b.found, 100);
    EXPECT_LT(std::abs(b.meanError), 0.01);
    EXPECT_LT(std::abs(b.meanOffset), 1.0);  // light scales: no offset
    const PatchTrack one = trackPatch(from, to, {200, 150}, {0, 0});
    ASSERT_TRUE(one.found);
    EXPECT_NEAR(one.gain, 0.85, 0.05);
}

TEST(PatchTracker, AWhiteLayerShowsAsAnOffset) {
    const cv::Size size(200, 200);
    const TrackingImage from = texturedView(size, {0, 0}, 1.0, 0.0, 0.4, 5);
    const TrackingImage to = texturedView(size, {0.5, 0}, 1.0, 0.2, 0.4, 6);  // 20 % blended towards white
    const PatchTrack t = trackPatch(from, to, {100, 100}, {0, 0});
    ASSERT_TRUE(t.found);
    EXPECT_GT(t.offset, 4.0 * t.offsetSigma);
    EXPECT_GT(t.offset, 20.0);
}

TEST(PatchTracker, RefusesWhatItCannotSee) {
    const TrackingImage flat = prepareForTracking(cv::Mat(100, 100, CV_32F, cv::Scalar(128)));
    EXPECT_FALSE(trackPatch(flat, flat, {50, 50}, {0, 0}).found);  // no texture
    const TrackingImage textured = texturedView({100, 100}, {0, 0}, 1.0, 0.0, 0.0, 7);
    EXPECT_FALSE(trackPatch(textured, textured, {5, 5}, {0, 0}).found);  // patch off the image
}

// The spline passes through every sample: the prefilter is exact.
TEST(PatchTracker, TheSplineInterpolatesTheSamples) {
    cv::Mat raw(90, 120, CV_32F);
    cv::randu(raw, 0, 255);  // the hardest case: no smoothness between the samples
    const TrackingImage whole = prepareForTracking(raw);
    for (int y = 20; y < 70; y += 7)
        for (int x = 20; x < 100; x += 9) {
            EXPECT_NEAR(splineValueAt(whole, {double(x), double(y)}), whole.grey.at<float>(y, x), 1e-3) << x << "," << y;
        }
    EXPECT_TRUE(std::isnan(splineValueAt(whole, {3.0, 40.0})));  // inside the prefilter's margin
}

TEST(PatchTracker, AWindowTracksAsTheWholeFrame) {
    const cv::Size size(300, 220);
    const TrackingImage from = texturedView(size, {0, 0}, 1.0, 0.0, 0.3, 1);
    const cv::Mat seen = sensorView(size, {0.6, -0.3}, 1.0, 0.0, 0.3, 2);
    const TrackingImage to = prepareForTracking(seen);
    // A window's own smoothing and prefilter differ from the frame's only near its edge (the
    // mirrored border's influence falls below 1e-7 within the prefilter's margin).
    const cv::Rect window(60, 40, 180, 140);
    const TrackingImage part = prepareForTracking(seen(window), window.tl());
    for (const cv::Point at : {cv::Point(150, 110), cv::Point(120, 90), cv::Point(180, 130)}) {
        const PatchTrack a = trackPatch(from, to, at, {0, 0});
        const PatchTrack b = trackPatch(from, part, at, {0, 0});
        ASSERT_TRUE(a.found && b.found) << at;
        EXPECT_NEAR(a.shift.x, b.shift.x, 1e-6);
        EXPECT_NEAR(a.shift.y, b.shift.y, 1e-6);
    }
    EXPECT_FALSE(trackPatch(from, part, {70, 110}, {0, 0}).found);  // the patch reaches out of the window
}

}  // namespace
}  // namespace icewatch::volume
