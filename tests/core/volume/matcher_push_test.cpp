#include "core/volume/matcher_push.hpp"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

namespace icewatch::volume {
namespace {

// A slanted surface's true disparity at (x, y).
double trueDisparity(double x, double y) { return 50.0 + 0.01 * x - 0.005 * y; }

cv::Mat disparityMap(cv::Size size, double push, cv::Rect pushed) {
    cv::Mat d(size, CV_32F);
    for (int y = 0; y < size.height; ++y)
        for (int x = 0; x < size.width; ++x) {
            d.at<float>(y, x) = static_cast<float>(trueDisparity(x, y) + (pushed.contains({x, y}) ? push : 0.0));
        }
    return d;
}

// Tracks on a grid whose disparities are exact, the current ones moved by (1.3, -0.4) px.
std::vector<TextureTrack> exactTracks(cv::Size size) {
    std::vector<TextureTrack> tracks;
    for (int y = 10; y < size.height - 10; y += 12)
        for (int x = 10; x < size.width - 10; x += 12) {
            TextureTrack t;
            t.pixel = {x, y};
            t.onObject = true;
            t.state = TextureTrack::State::Unchanged;
            t.baselineDisparity = trueDisparity(x, y);
            t.currentPixel = {x + 1.3, y - 0.4};
            t.currentDisparity = trueDisparity(x + 1.3, y - 0.4);
            tracks.push_back(t);
        }
    return tracks;
}

TEST(MatcherPush, MeasuresTheMatchersExtraChangeOnCleanTexture) {
    const cv::Size size(200, 160);
    const auto tracks = exactTracks(size);
    const std::vector<std::uint8_t> clean(tracks.size(), 1);
    const cv::Mat everywhere(size, CV_8U, cv::Scalar(255));
    const cv::Mat baseline = disparityMap(size, 0.0, {});
    // The current surface pushed forward by 0.1 px everywhere: the tracks say it did not move so.
    const MatcherPush p = matcherPush(tracks, clean, baseline, disparityMap(size, 0.1, {{0, 0}, size}), everywhere, 4.0);
    EXPECT_EQ(p.samples, static_cast<int>(tracks.size()));
    EXPECT_NEAR(p.meanPx, 0.1, 1e-4);
    EXPECT_LT(p.sigmaPx, 1e-4);
    // A matcher that follows the tracks shows no push.
    EXPECT_NEAR(matcherPush(tracks, clean, baseline, baseline, everywhere, 4.0).meanPx, 0.0, 1e-4);
}

TEST(MatcherPush, CountsOnlyCleanObjectSamplesWhereTheVolumeIsIntegrated) {
    const cv::Size size(200, 160);
    auto tracks = exactTracks(size);
    std::vector<std::uint8_t> clean(tracks.size(), 1);
    // The push lies in the left half; the integration mask is the right half.
    const cv::Rect left(0, 0, 100, 160);
    const cv::Mat current = disparityMap(size, 0.3, left);
    cv::Mat rightHalf(size, CV_8U, cv::Scalar(0));
    rightHalf(cv::Rect(100, 0, 100, 160)).setTo(255);
    const cv::Mat baseline = disparityMap(size, 0.0, {});
    EXPECT_NEAR(matcherPush(tracks, clean, baseline, current, rightHalf, 1.0).meanPx, 0.0, 1e-4);
    // Samples that are not clean evidence, or on the background, do not count.
    const cv::Mat everywhere(size, CV_8U, cv::Scalar(255));
    for (std::size_t i = 0; i < tracks.size(); ++i) {
        if (!left.contains(tracks[i].pixel)) continue;
        if (i % 2) clean[i] = 0;
        else tracks[i].onObject = false;
    }
    const MatcherPush p = matcherPush(tracks, clean, baseline, current, everywhere, 1.0);
    EXPECT_GT(p.samples, 0);
    EXPECT_LT(p.samples, static_cast<int>(tracks.size()));
    EXPECT_NEAR(p.meanPx, 0.0, 0.01);  // the left half's samples all left out (the current pixel may cross by 1.3 px)
}

TEST(MatcherPush, ItsErrorFollowsTheScatterAndTheCorrelation) {
    const cv::Size size(240, 200);
    const auto tracks = exactTracks(size);
    const std::vector<std::uint8_t> clean(tracks.size(), 1);
    const cv::Mat everywhere(size, CV_8U, cv::Scalar(255));
    cv::Mat current = disparityMap(size, 0.0, {});
    cv::Mat noise(size, CV_32F);
    cv::RNG(7).fill(noise, cv::RNG::NORMAL, 0.0, 0.2);
    current += noise;
    const MatcherPush one = matcherPush(tracks, clean, disparityMap(size, 0.0, {}), current, everywhere, 1.0);
    const MatcherPush four = matcherPush(tracks, clean, disparityMap(size, 0.0, {}), current, everywhere, 4.0);
    // Independent pixel noise of 0.2 read bilinearly at fractions (0.3, 0.6): a single sample
    // scatters by 0.2·√((0.7² + 0.3²)(0.4² + 0.6²)) = 0.2·0.55.
    const double expected = 0.2 * 0.55 / std::sqrt(static_cast<double>(one.samples));
    EXPECT_NEAR(one.sigmaPx, expected, 0.3 * expected);
    EXPECT_NEAR(four.sigmaPx, 2.0 * one.sigmaPx, 1e-9);
    EXPECT_LT(std::abs(one.meanPx), 4.0 * one.sigmaPx);
}

}  // namespace
}  // namespace icewatch::volume
