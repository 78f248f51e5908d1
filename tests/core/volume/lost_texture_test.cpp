#include "core/volume/lost_texture.hpp"

#include <gtest/gtest.h>

#include "core/synth/texture.hpp"
#include "core/volume/patch_tracker.hpp"

namespace icewatch::volume {
namespace {

const cv::Size kSize(240, 160);
constexpr double kDisparity = 12.0;

// A current capture whose left half carries texture and whose right half (x >= 120) is plain, as
// opaque ice without texture of its own, seen `shiftX` px to the left.
cv::Mat view(double shiftX) {
    cv::Mat image(kSize, CV_32F);
    for (int y = 0; y < kSize.height; ++y)
        for (int x = 0; x < kSize.width; ++x) {
            const double textured = 120.0 + 25.0 * synth::fractalNoise(x + shiftX, y, 9.0, 3, 11);
            image.at<float>(y, x) = static_cast<float>(x + shiftX < 120 ? textured : 210.0);
        }
    return image;
}

TextureTrack lostAt(cv::Point pixel) {
    TextureTrack t;
    t.pixel = pixel;
    t.onObject = true;
    t.inBaseline = true;
    t.state = TextureTrack::State::Untracked;
    return t;
}

TEST(LostTexture, OnlyWhereStereoCannotReadWhatHidTheTexture) {
    const RectifiedCapture current{prepareForTracking(view(0)), prepareForTracking(view(kDisparity)),
                                   cv::Mat(kSize, CV_32F, cv::Scalar(kDisparity))};
    TextureTrackOptions options;
    options.stepPx = 12;
    const cv::Point onTexture(60, 80), onPlain(180, 80);
    const auto unmoved = [](cv::Point2d px) { return px; };
    const cv::Mat unread = unreadLostTexture({lostAt(onTexture), lostAt(onPlain)}, current, unmoved, options);
    ASSERT_EQ(unread.size(), kSize);
    EXPECT_EQ(unread.at<std::uint8_t>(onTexture), 0);  // textured ice of its own: stereo reads it
    EXPECT_EQ(unread.at<std::uint8_t>(onPlain), 255);
    EXPECT_EQ(cv::countNonZero(unread), options.stepPx * options.stepPx);

    // Texture found again, glimpsed, off the object or never there to follow says nothing.
    TextureTrack found = lostAt(onPlain), glimpsed = lostAt(onPlain), background = lostAt(onPlain),
                 untextured = lostAt(onPlain);
    found.state = TextureTrack::State::Changed;
    glimpsed.glimpsed = true;
    background.onObject = false;
    untextured.inBaseline = false;
    EXPECT_EQ(cv::countNonZero(unreadLostTexture({found, glimpsed, background, untextured}, current, unmoved, options)), 0);

    // Looked for where the object went; a place off the frame is not looked at.
    const cv::Mat moved = unreadLostTexture({lostAt(onTexture)}, current,
                                            [](cv::Point2d px) { return px + cv::Point2d(120, 0); }, options);
    EXPECT_EQ(moved.at<std::uint8_t>(onPlain), 255);
    const cv::Mat far = unreadLostTexture({lostAt(onPlain)}, current, [](cv::Point2d) { return cv::Point2d(1e30, 5); }, options);
    EXPECT_EQ(cv::countNonZero(far), 0);
}

}  // namespace
}  // namespace icewatch::volume
