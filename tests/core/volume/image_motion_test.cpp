#include "core/volume/image_motion.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "core/synth/texture.hpp"

namespace icewatch::volume {
namespace {

const cv::Size kSize(400, 240);
const cv::Rect kObject(150, 90, 100, 60);

// An image of `size` whose pixels each average n x n samples of the continuous scene `greyAt(x, y)`
// (pixel centres on whole numbers), so that sub-pixel motions are exact.
template <class GreyAt>
cv::Mat supersampled(cv::Size size, int n, const GreyAt& greyAt) {
    cv::Mat image(size, CV_32F);
    for (int y = 0; y < size.height; ++y)
        for (int x = 0; x < size.width; ++x) {
            double grey = 0;
            for (int j = 0; j < n; ++j)
                for (int i = 0; i < n; ++i) grey += greyAt(x + (i + 0.5) / n - 0.5, y + (j + 0.5) / n - 0.5);
            image.at<float>(y, x) = static_cast<float>(grey / (n * n));
        }
    return image;
}

// An object with a weak texture of its own, seen moved by `objectShift`, on a background with a
// strong texture moved by `backgroundShift`.
cv::Mat scene(cv::Point2d objectShift, cv::Point2d backgroundShift) {
    return supersampled(kSize, 4, [&](double px, double py) {
        const double ox = px - objectShift.x, oy = py - objectShift.y;
        if (kObject.contains(cv::Point(static_cast<int>(std::floor(ox + 0.5)), static_cast<int>(std::floor(oy + 0.5)))))
            return 140.0 + 6.0 * synth::fractalNoise(ox, oy, 6.0, 3, 5);
        return 110.0 + 60.0 * synth::fractalNoise(px - backgroundShift.x, py - backgroundShift.y, 12.0, 3, 9);
    });
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

// A long object (a blade's stretch across the image) with a weak texture of its own over an even
// sky, turned by `turnDeg` about its centre and moved by `shift`; `iced` covers parts of it with a
// whiter texture of another pattern (ice that appeared).
const cv::Size kWide(900, 300);
const cv::Rect kLong(100, 100, 700, 100);

cv::Matx23d turnAndShift(double turnDeg, cv::Point2d shift) {
    const cv::Point2d centre(kLong.x + 0.5 * kLong.width, kLong.y + 0.5 * kLong.height);
    const double c = std::cos(turnDeg * CV_PI / 180.0), s = std::sin(turnDeg * CV_PI / 180.0);
    return {c, -s, centre.x - c * centre.x + s * centre.y + shift.x,  //
            s, c, centre.y - s * centre.x - c * centre.y + shift.y};
}

cv::Mat longObject(const cv::Matx23d& motion, const std::vector<cv::Rect>& iced = {}) {
    const cv::Matx33d forward(motion(0, 0), motion(0, 1), motion(0, 2), motion(1, 0), motion(1, 1), motion(1, 2), 0, 0, 1);
    const cv::Matx33d back = forward.inv();
    return supersampled(kWide, 2, [&](double px, double py) {
        const cv::Vec3d p = back * cv::Vec3d(px, py, 1);
        const cv::Point2d o(p[0], p[1]);
        if (!cv::Rect2d(kLong).contains(o)) return 200.0;
        for (const cv::Rect& r : iced)
            if (cv::Rect2d(r).contains(o)) return 215.0 + 12.0 * synth::fractalNoise(o.x, o.y, 5.0, 3, 77);
        return 140.0 + 6.0 * synth::fractalNoise(o.x, o.y, 6.0, 3, 5);
    });
}

cv::Mat longMask() {
    cv::Mat mask(kWide, CV_8U, cv::Scalar(0));
    mask(kLong).setTo(255);
    return mask;
}

// The farthest the two maps put a corner of the object apart.
double cornerError(const cv::Matx23d& found, const cv::Matx23d& truth) {
    double worst = 0;
    for (const cv::Point2d corner : {cv::Point2d(kLong.tl()), cv::Point2d(kLong.br()), cv::Point2d(kLong.x, kLong.br().y),
                                     cv::Point2d(kLong.br().x, kLong.y)})
        worst = std::max(worst, cv::norm(mapped(found, corner) - mapped(truth, corner)));
    return worst;
}

TEST(ObjectImageMotion, FollowsATurnThatMovesTheEndsBeyondTheTrackersSearch) {
    // 1.5° about the centre moves the ends 9 px up and down against the object's shift: outside the
    // 8 px the trackers search around a single shift. A third of the object iced over.
    const cv::Matx23d truth = turnAndShift(1.5, {7.0, 3.0});
    const cv::Mat before = longObject(turnAndShift(0, {0, 0}));
    const cv::Mat after = longObject(truth, {cv::Rect(kLong.x + 250, kLong.y, 230, kLong.height)});
    const cv::Point2d shift = globalImageShift(before, after, longMask());
    const cv::Point2d fallback = confirmedShift(before, after, longMask(), shift);
    ASSERT_GT(cornerError(translation(fallback), truth), 8.0);
    // A start for the trackers: well inside their search, from the ice-free two thirds.
    EXPECT_LT(cornerError(objectImageMotion(before, after, longMask(), shift, fallback), truth), 1.0);
}

TEST(GlobalImageShift, FindsAShiftOfTensOfPixelsUnderNewIce) {
    // Moved (18, -12) px, turned 0.5°, bright ice over half of it: at a quarter of the resolution
    // the ice's own outline wins the correlation (-39, 9), at full resolution the texture does. The
    // other way round (rime patches on a rendered blade, full resolution fooled) is
    // VolumeChain.RimePatchesOnABladeParkedAtAnotherPitchAreMeasured.
    const cv::Matx23d truth = turnAndShift(0.5, {18.0, -12.0});
    const cv::Mat before = longObject(turnAndShift(0, {0, 0}));
    const cv::Mat after = longObject(truth, {cv::Rect(kLong.x + 100, kLong.y, 350, kLong.height)});
    const cv::Point2d shift = globalImageShift(before, after, longMask());
    EXPECT_NEAR(shift.x, 18.0, 2.0);
    EXPECT_NEAR(shift.y, -12.0, 2.0);
}

TEST(ObjectImageMotion, AnObjectTooSmallForTilesKeepsTheShift) {
    const cv::Mat before = scene({0, 0}, {0, 0}), after = scene({2, 1}, {2, 1});
    const cv::Matx23d motion = objectImageMotion(before, after, objectMask(), {2.2, 0.9}, {2.2, 0.9});
    EXPECT_EQ(cornerError(motion, translation({2.2, 0.9})), 0.0);
}

}  // namespace
}  // namespace icewatch::volume
