#include <fstream>

#include <gtest/gtest.h>

#include "core/common/error.hpp"
#include "core/stereo/disparity_io.hpp"
#include "core/stereo/evaluation.hpp"
#include "core/stereo/matcher.hpp"
#include "tests/support/test_paths.hpp"

namespace icewatch::stereo {
namespace {

TEST(Score, BadPixelsInsideTheMaskWithKnownTruth) {
    const cv::Mat disparity = (cv::Mat_<float>(1, 5) << 10.0f, 10.0f, -1.0f, 3.0f, 7.0f);
    const cv::Mat gt = (cv::Mat_<std::uint8_t>(1, 5) << 40, 46, 40, 0, 40);        // scale 4: 10, 11.5, 10, ?, 10
    const cv::Mat mask = (cv::Mat_<std::uint8_t>(1, 5) << 255, 255, 255, 255, 0);  // last not evaluated
    const DisparityScore s = scoreDisparity(disparity, gt, 4.0, mask, 1.0);
    EXPECT_EQ(s.evaluated, 3);                       // x = 3 has no truth, x = 4 is masked
    EXPECT_NEAR(s.badPercent, 100.0 * 2 / 3, 1e-9);  // 11.5 is 1.5 away; the missing one is bad
    EXPECT_NEAR(s.validPercent, 80.0, 1e-9);
}

TEST(Noise, ParsesAndIsReproducible) {
    EXPECT_EQ(parseNoise("none").kind, NoiseSpec::Kind::None);
    EXPECT_EQ(parseNoise("saltpepper:3").amount, 3.0);
    EXPECT_EQ(parseNoise("gauss:2.5").kind, NoiseSpec::Kind::Gaussian);
    EXPECT_THROW(parseNoise("salt"), InvalidInput);
    EXPECT_THROW(parseNoise("gauss:x"), InvalidInput);
    EXPECT_THROW(parseNoise("saltpepper:300"), InvalidInput);
    EXPECT_THROW(parseNoise("gauss:2x"), InvalidInput);

    const cv::Mat clean(200, 200, CV_8UC3, cv::Scalar::all(128));
    cv::Mat a = clean.clone(), b = clean.clone(), c = clean.clone();
    addNoise(a, parseNoise("saltpepper:10"), 5);
    addNoise(b, parseNoise("saltpepper:10"), 5);
    addNoise(c, parseNoise("saltpepper:10"), 6);
    EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
    EXPECT_GT(cv::norm(a, c, cv::NORM_INF), 0.0);
    cv::Mat grey;
    cv::extractChannel(a, grey, 0);
    const double changed = 100.0 * (cv::countNonZero(grey == 0) + cv::countNonZero(grey == 255)) / grey.total();
    EXPECT_NEAR(changed, 10.0, 1.0);
    EXPECT_NEAR(cv::countNonZero(grey == 0), cv::countNonZero(grey == 255), 0.2 * cv::countNonZero(grey == 0));

    cv::Mat g = clean.clone();
    addNoise(g, parseNoise("gauss:4"), 7);
    cv::Mat diff;
    cv::Mat(g - clean + cv::Scalar::all(0)).convertTo(diff, CV_32F);
    cv::Mat signedDiff;
    g.convertTo(signedDiff, CV_32F);
    signedDiff -= cv::Scalar::all(128);
    cv::Scalar mean, stddev;
    cv::meanStdDev(signedDiff.reshape(1), mean, stddev);
    EXPECT_NEAR(stddev[0], 4.0, 0.2);
    EXPECT_NEAR(mean[0], 0.0, 0.1);
}

TEST(Pfm, RoundTripKeepsValuesAndInvalidPixels) {
    const auto dir = icewatch::test::freshTempDir();
    cv::Mat d(3, 4, CV_32FC1);
    cv::randu(d, 0.0f, 60.0f);
    d.at<float>(1, 2) = kInvalidDisparity;
    writePfm(dir / "d.pfm", d);
    const cv::Mat back = readPfm(dir / "d.pfm");
    ASSERT_EQ(back.size(), d.size());
    EXPECT_EQ(cv::norm(back, d, cv::NORM_INF), 0.0);
    EXPECT_THROW(readPfm(dir / "missing.pfm"), Error);
    std::ofstream(dir / "bad.pfm") << "P6\n3 3\n255\n";
    EXPECT_THROW(readPfm(dir / "bad.pfm"), Error);
    std::ofstream(dir / "short.pfm") << "Pf\n3 3\n-1.0\nabc";
    EXPECT_THROW(readPfm(dir / "short.pfm"), Error);
    const cv::Mat colour = colorizeDisparity(d, 64);
    EXPECT_EQ(colour.type(), CV_8UC3);
    EXPECT_EQ(colour.at<cv::Vec3b>(1, 2), cv::Vec3b(0, 0, 0));
}

}  // namespace
}  // namespace icewatch::stereo
