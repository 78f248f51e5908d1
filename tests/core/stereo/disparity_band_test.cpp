// Matching a band of disparities [min, max): the same answer as the full range wherever the truth
// lies inside the band, invalid (not clamped to the edge) where it lies outside; and the band's
// arguments checked.
#include <cstring>
#include <limits>

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "core/common/error.hpp"
#include "core/stereo/matcher.hpp"
#include "tests/core/stereo/stereo_test_images.hpp"

namespace icewatch::stereo {
namespace {

// A pair at an awkward size whose left eye sees the right one's texture shifted by the
// disparity map `truth` (linear interpolation): a slanted background plane and a nearer box.
struct BandPair {
    cv::Mat left, right, truth;
};

BandPair bandPair(int width, int height, float backgroundNear, float backgroundFar, float box, int channels) {
    BandPair pair;
    pair.right = test::randomImage(width, height, channels == 3 ? CV_8UC3 : CV_8UC1, 23);
    pair.truth.create(height, width, CV_32FC1);
    const cv::Rect boxArea(width / 3, height / 4, width / 3, height / 2);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const float plane = backgroundNear + (backgroundFar - backgroundNear) * x / static_cast<float>(width - 1);
            pair.truth.at<float>(y, x) = boxArea.contains({x, y}) ? box : plane;
        }
    cv::Mat mapX(height, width, CV_32FC1), mapY(height, width, CV_32FC1);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            mapX.at<float>(y, x) = static_cast<float>(x) - pair.truth.at<float>(y, x);
            mapY.at<float>(y, x) = static_cast<float>(y);
        }
    cv::remap(pair.right, pair.left, mapX, mapY, cv::INTER_LINEAR, cv::BORDER_REFLECT);
    return pair;
}

// Pixels of `a` and `b` inside `area` that differ in any bit (both invalid counts as equal).
int differingPixels(const cv::Mat& a, const cv::Mat& b, const cv::Rect& area) {
    int differing = 0;
    for (int y = area.y; y < area.y + area.height; ++y)
        for (int x = area.x; x < area.x + area.width; ++x) differing += a.at<float>(y, x) != b.at<float>(y, x);
    return differing;
}

TEST(DisparityBand, EqualsTheFullRangeWhereTheTruthIsInside) {
    // Truth 19 .. 28 and 33 on a 203x77 pair, against the full range with the same maximum. The
    // costs are the full range's cell for cell; the scanline sums are the same wherever each
    // path's least sum lies inside the band, which a well textured pair gives. OpenCV's SGBM
    // searches a multiple of 16 disparities, so its full range [0, 37) searches up to 47 and its
    // band [11, 37) from 5 to 36: it is held to [16, 48) against [0, 48), which it searches as
    // asked, on the colour pair. (On the grey one 7 pixels below the box differ by 1/16 px: the
    // sums there felt the disparities below 16.)
    struct Case {
        Method method;
        DisparityRange band;
    };
    const Case cases[] = {{Method::Paper, {11, 37}},    {Method::AdCensus, {11, 37}}, {Method::Paper, {16, 48}},
                          {Method::AdCensus, {16, 48}}, {Method::Sgbm, {16, 48}}};
    for (const int channels : {3, 1}) {
        const BandPair pair = bandPair(203, 77, 19.0f, 28.0f, 33.0f, channels);
        for (const Case& c : cases) {
            if (c.method == Method::Sgbm && channels == 1) continue;
            const std::string what = methodName(c.method) + " [" + std::to_string(c.band.min) + ", " +
                                     std::to_string(c.band.max) + "), " + std::to_string(channels) + " channels";
            Matcher full(c.method), banded(c.method);
            const cv::Mat expected = full.compute(pair.left, pair.right, DisparityRange{0, c.band.max});
            const cv::Mat actual = banded.compute(pair.left, pair.right, c.band);
            ASSERT_EQ(actual.size(), pair.left.size());
            ASSERT_EQ(actual.type(), CV_32FC1);
            // Away from the image's borders, where each view has pixels the other does not see and
            // the aggregation's reach differs (OpenCV's SGBM leaves the columns left of 48
            // unmatched and fills them).
            const cv::Rect inside(56, 0, 203 - 56 - 8, 77);
            EXPECT_EQ(differingPixels(expected, actual, inside), 0) << what;
            // Left of the band's minimum no right pixel lies in the band.
            for (int y = 0; y < 77; ++y)
                for (int x = 0; x < c.band.min; ++x) ASSERT_EQ(actual.at<float>(y, x), kInvalidDisparity) << what;
        }
    }
}

// The truth (a slanted plane, 21 .. 22) just outside the band, above it and below it: the
// cost still falls towards the truth at the band's edge, so the best match sits there, and those
// pixels are reported invalid instead of being clamped to the edge.
TEST(DisparityBand, ABandThatMissesTheTruthMarksItsPixelsInvalid) {
    const BandPair pair = bandPair(203, 77, 21.0f, 22.0f, 21.5f, 3);
    for (const Method method : {Method::Paper, Method::AdCensus, Method::Sgbm}) {
        for (const DisparityRange band : {DisparityRange{23, 45}, DisparityRange{2, 21}}) {
            Matcher matcher(method);
            const cv::Mat d = matcher.compute(pair.left, pair.right, band);
            int invalid = 0, total = 0;
            for (int y = 5; y < 72; ++y)
                for (int x = 50; x < 198; ++x) {
                    const float v = d.at<float>(y, x);
                    ++total;
                    invalid += v == kInvalidDisparity;
                }
            // Measured: all of them, but for 48 of AD-Census' below the band.
            EXPECT_GT(invalid, total * 98 / 100) << methodName(method) << " [" << band.min << ", " << band.max << ")";
        }
    }
}

TEST(DisparityBand, RejectsBandsItCannotSearch) {
    const cv::Mat a(10, 20, CV_8UC3, cv::Scalar::all(1));
    for (const Method method : {Method::Paper, Method::Sgbm}) {
        Matcher matcher(method);
        EXPECT_THROW(matcher.compute(a, a, DisparityRange{-1, 8}), InvalidInput);
        EXPECT_THROW(matcher.compute(a, a, DisparityRange{5, 5}), InvalidInput);
        EXPECT_THROW(matcher.compute(a, a, DisparityRange{6, 5}), InvalidInput);
        EXPECT_THROW(matcher.compute(a, a, DisparityRange{5, 7}), InvalidInput);  // two: no interior
        EXPECT_THROW(matcher.compute(a, a, DisparityRange{10, 20}), InvalidInput);  // max not below the width
        EXPECT_NO_THROW(matcher.compute(a, a, DisparityRange{16, 19}));  // flat, tiny, but legal
    }
    try {
        Matcher(Method::Paper).compute(a, a, DisparityRange{5, 7});
    } catch (const InvalidInput& e) {
        EXPECT_NE(std::string(e.what()).find("[5, 7)"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace icewatch::stereo
