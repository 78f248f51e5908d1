#include "core/volume/texture_tracks.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "core/synth/texture.hpp"

namespace icewatch::volume {
namespace {

const cv::Size kSize(400, 240);
const cv::Rect kObject(150, 90, 100, 60);

// An object with a weak texture of its own, seen moved by `objectShift`, on a background with a
// strong texture moved by `backgroundShift`. Each pixel averages 4x4 samples of the continuous
// textures, so sub-pixel shifts are exact.
cv::Mat scene(cv::Point2d objectShift, cv::Point2d backgroundShift) {
    constexpr int kSamples = 4;
    cv::Mat image(kSize, CV_32F);
    for (int y = 0; y < kSize.height; ++y)
        for (int x = 0; x < kSize.width; ++x) {
            double grey = 0;
            for (int j = 0; j < kSamples; ++j)
                for (int i = 0; i < kSamples; ++i) {
                    const double px = x + (i + 0.5) / kSamples - 0.5, py = y + (j + 0.5) / kSamples - 0.5;
                    const double ox = px - objectShift.x, oy = py - objectShift.y;
                    if (kObject.contains(cv::Point(static_cast<int>(std::floor(ox + 0.5)), static_cast<int>(std::floor(oy + 0.5))))) {
                        grey += 140.0 + 6.0 * synth::fractalNoise(ox, oy, 6.0, 3, 5);
                    } else {
                        grey += 110.0 + 60.0 * synth::fractalNoise(px - backgroundShift.x, py - backgroundShift.y, 12.0, 3, 9);
                    }
                }
            image.at<float>(y, x) = static_cast<float>(grey / (kSamples * kSamples));
        }
    return image;
}

cv::Mat objectMask() {
    cv::Mat mask(kSize, CV_8U, cv::Scalar(0));
    mask(kObject).setTo(255);
    return mask;
}

TEST(ConfirmedShift, FindsHowTheObjectMoved) {
    const cv::Point2d moved(2.5, -1.25);
    const cv::Mat before = scene({0, 0}, {0, 0}), after = scene(moved, moved);
    const cv::Point2d shift = confirmedShift(before, after, objectMask(), globalImageShift(before, after, objectMask()));
    // A start for the trackers, which search 8 px around it: OpenCV's sub-pixel peak is not exact.
    EXPECT_NEAR(shift.x, moved.x, 1.0);
    EXPECT_NEAR(shift.y, moved.y, 1.0);
    EXPECT_GT(std::hypot(shift.x, shift.y), 1.0);
}

TEST(ConfirmedShift, APeakTheObjectDoesNotShareIsNotBelieved) {
    // The object stayed; what moved 20 px is the strongly textured rest of its box (a sky's
    // clouds; a JPEG's blocks are another pattern the correlation may lock onto): the object
    // correlates best in place, and the trackers start there.
    const cv::Mat before = scene({0, 0}, {0, 0}), after = scene({0, 0}, {20, 0});
    EXPECT_EQ(confirmedShift(before, after, objectMask(), {20, 0}), cv::Point2d(0, 0));
    EXPECT_EQ(confirmedShift(before, after, objectMask(), {25.2, 0.5}), cv::Point2d(0, 0));
    // Where the object did move by it, the shift stands.
    const cv::Mat moved = scene({20, 0}, {20, 0});
    EXPECT_EQ(confirmedShift(before, moved, objectMask(), {20, 0}), cv::Point2d(20, 0));
}

}  // namespace
}  // namespace icewatch::volume
