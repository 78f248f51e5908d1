#include "core/volume/texture_tracks.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "core/synth/texture.hpp"
#include "core/volume/image_motion.hpp"

namespace icewatch::volume {
namespace {

const cv::Size kSize(240, 160);
constexpr double kDisparity = 12.0, kFocalPx = 800.0, kBaselineMm = 60.0;

// A noise-free texture seen `shiftX` px to the left.
cv::Mat view(double shiftX) {
    cv::Mat image(kSize, CV_32F);
    for (int y = 0; y < kSize.height; ++y)
        for (int x = 0; x < kSize.width; ++x)
            image.at<float>(y, x) = static_cast<float>(120.0 + 25.0 * synth::fractalNoise(x + shiftX, y, 9.0, 3, 11));
    return image;
}

// The same capture twice, free of noise: every patch matches its twin exactly, so its own residual
// says it is perfectly placed. The pairs must still carry the tracker's own error, or the fit
// would rest all its weight on them and its covariance would not be invertible.
TEST(TextureTracks, IdenticalNoiseFreeCapturesStillCarryTheTrackersOwnError) {
    RectifiedCapture capture{prepareForTracking(view(0)), prepareForTracking(view(kDisparity)),
                             cv::Mat(kSize, CV_32F, cv::Scalar(kDisparity))};
    cv::Matx44d q = cv::Matx44d::zeros();
    q(0, 0) = q(1, 1) = 1.0;
    q(0, 3) = -kSize.width / 2.0;
    q(1, 3) = -kSize.height / 2.0;
    q(2, 3) = kFocalPx;
    q(3, 2) = 1.0 / kBaselineMm;
    TextureTrackOptions options;
    options.stepPx = 20;
    const cv::Mat object(kSize, CV_8U, cv::Scalar(255));
    const BaselineSamples samples = baselineSamples(capture, object, options);
    TextureTrackOptions noFloor = options;
    noFloor.minShiftSigmaPx = 0;
    const std::vector<TextureTrack> tracks =
        trackTexture(samples, capture, capture, q, translation({0, 0}), 1.0, options);
    const std::vector<TextureTrack> bare = trackTexture(samples, capture, capture, q, translation({0, 0}), 1.0, noFloor);
    ASSERT_EQ(tracks.size(), bare.size());
    const double mmPerPx = kBaselineMm / kDisparity;  // across the view at this depth
    const double depthMmPerPx = kFocalPx * kBaselineMm / (kDisparity * kDisparity);
    int unchanged = 0;
    for (std::size_t i = 0; i < tracks.size(); ++i) {
        const TextureTrack& t = tracks[i];
        if (t.state != TextureTrack::State::Unchanged) continue;
        ++unchanged;
        EXPECT_NEAR(cv::norm(t.currentMm - t.baselineMm), 0.0, 1e-3);
        // What the patch's own residual says: far better than any tracker places a patch.
        EXPECT_LT(std::sqrt(bare[i].covarianceMm2(1, 1)), 0.1 * options.minShiftSigmaPx * mmPerPx);
        // Across the view (y): the floor of one eye's track; in depth: both eyes', through Q.
        EXPECT_GE(std::sqrt(t.covarianceMm2(1, 1)), 0.99 * options.minShiftSigmaPx * mmPerPx);
        EXPECT_GE(std::sqrt(t.covarianceMm2(2, 2)), 0.99 * std::sqrt(2.0) * options.minShiftSigmaPx * depthMmPerPx);
    }
    EXPECT_GT(unchanged, 20);
}

}  // namespace
}  // namespace icewatch::volume
