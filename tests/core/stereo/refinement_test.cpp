#include <cmath>

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "core/stereo/matcher.hpp"
#include "core/stereo/stages.hpp"
#include "tests/core/stereo/stereo_test_images.hpp"

namespace icewatch::stereo::detail {
namespace {

cv::Mat row16(const std::vector<int>& values) {
    cv::Mat m(1, static_cast<int>(values.size()), CV_16SC1);
    for (int x = 0; x < m.cols; ++x) m.at<std::int16_t>(0, x) = static_cast<std::int16_t>(values[static_cast<std::size_t>(x)]);
    return m;
}

TEST(WinnerTakesAll, LeftAndRightViews) {
    CostVolume v;
    v.create(4, 1, 3);
    std::fill(v.data.begin(), v.data.end(), 100);
    v.at(0, 0)[0] = 5;
    v.at(1, 0)[1] = 5;   // left x = 1 sees right x = 0 at d = 1
    v.at(2, 0)[1] = 5;
    v.at(3, 0)[2] = 5;   // right x = 1 at d = 2
    v.at(3, 0)[0] = 50;  // worse than 5
    cv::Mat left, right;
    winnerTakesAll(v, left, right);
    EXPECT_EQ(left.at<std::int16_t>(0, 0), 0);
    EXPECT_EQ(left.at<std::int16_t>(0, 1), 1);
    EXPECT_EQ(left.at<std::int16_t>(0, 3), 2);
    // Right x = 0: candidates (x=0,d=0) 5 and (x=1,d=1) 5 tie: the smaller disparity wins.
    EXPECT_EQ(right.at<std::int16_t>(0, 0), 0);
    EXPECT_EQ(right.at<std::int16_t>(0, 1), 1);  // (2,1) = 5 beats (1,0) = 100 and (3,2) = 5 ties later
    EXPECT_EQ(right.at<std::int16_t>(0, 3), 0);  // only (3,0) exists
}

TEST(LeftRightCheck, ConsistencyAndOcclusionVersusMismatch) {
    const cv::Mat left = row16({0, 1, 1, 1, 3, 1, 1, 1});
    const cv::Mat right = row16({2, 0, 1, 1, 1, 1, 1, 1});
    const cv::Mat labels = leftRightCheck(left, right, 4, 1);
    // x = 0: R(0) = 2 differs by 2, and no right pixel maps back to x = 0: occluded.
    EXPECT_EQ(labels.at<std::uint8_t>(0, 0), kOccluded);
    EXPECT_EQ(labels.at<std::uint8_t>(0, 1), kReliable);  // |1 - R(0)| = 1 <= δ
    EXPECT_EQ(labels.at<std::uint8_t>(0, 2), kReliable);
    // x = 4: d = 3 but R(1) = 0; yet R(3) = 1 maps back to x = 4: mismatched.
    EXPECT_EQ(labels.at<std::uint8_t>(0, 4), kMismatched);
    EXPECT_EQ(labels.at<std::uint8_t>(0, 7), kReliable);
    EXPECT_EQ(leftRightCheck(left, right, 4, 0).at<std::uint8_t>(0, 1), kMismatched);  // δ = 0
}

TEST(RegionVoting, TakesTheMajorityOfTheRegion) {
    const cv::Mat image(5, 5, CV_8UC3, cv::Scalar::all(60));  // one region: the whole image
    CrossArms arms;
    computeCrossArms(image, Parameters{}, arms);
    cv::Mat disparity(5, 5, CV_16SC1, cv::Scalar(3));
    disparity(cv::Rect(0, 0, 4, 1)).setTo(7);  // 4 of 24 reliable say 7, 20 say 3
    cv::Mat labels = cv::Mat::zeros(5, 5, CV_8UC1);
    labels.at<std::uint8_t>(2, 2) = kMismatched;
    disparity.at<std::int16_t>(2, 2) = 9;
    Parameters parameters;
    parameters.votingMinCount = 20;  // 24 reliable > 20
    parameters.votingMinRatio = 0.4;  // 20 / 24 > 0.4
    cv::Mat d = disparity.clone(), l = labels.clone();
    EXPECT_EQ(regionVoting(arms, parameters, d, l), 1);
    EXPECT_EQ(d.at<std::int16_t>(2, 2), 3);
    EXPECT_EQ(l.at<std::uint8_t>(2, 2), kReliable);
    // Too few reliable pixels for a vote: nothing changes.
    parameters.votingMinCount = 24;
    d = disparity.clone();
    l = labels.clone();
    EXPECT_EQ(regionVoting(arms, parameters, d, l), 0);
    EXPECT_EQ(d.at<std::int16_t>(2, 2), 9);
    // No clear majority: nothing changes either.
    parameters.votingMinCount = 20;
    parameters.votingMinRatio = 0.9;
    d = disparity.clone();
    l = labels.clone();
    EXPECT_EQ(regionVoting(arms, parameters, d, l), 0);
}

TEST(RegionVoting, OptimisedEqualsReference) {
    // Smooth colours (long arms, regions of hundreds of pixels) over a disparity map of a few
    // patches with noise, at an awkward size; outliers dense (a third: columns take the prefix
    // way) and sparse (1 in 40: most columns visit their few regions directly); several
    // iterations, and thresholds that let some votes pass and stop others.
    cv::Mat image = test::randomImage(211, 97, CV_8UC3, 8);
    cv::GaussianBlur(image, image, cv::Size(0, 0), 2.5);
    CrossArms arms;
    computeCrossArms(image, Parameters{}, arms);
    for (const int oneIn : {3, 40}) {
        cv::RNG rng(12);
        cv::Mat disparity(image.size(), CV_16SC1), labels(image.size(), CV_8UC1);
        for (int y = 0; y < image.rows; ++y)
            for (int x = 0; x < image.cols; ++x) {
                const int patch = 10 + 7 * ((x / 40 + y / 30) % 4);
                const int noise = rng.uniform(0, 3) == 0 ? rng.uniform(-2, 3) : 0;  // the patch's value wins ~70 %
                disparity.at<std::int16_t>(y, x) = static_cast<std::int16_t>(patch + noise);
                const bool outlier = rng.uniform(0, oneIn) == 0;
                labels.at<std::uint8_t>(y, x) = outlier ? (rng.uniform(0, 2) ? kOccluded : kMismatched) : kReliable;
            }
        for (const double ratio : {0.3, 0.7}) {
            Parameters parameters;
            parameters.votingMinCount = 20;
            parameters.votingMinRatio = ratio;
            parameters.votingIterations = 4;
            cv::Mat fastD = disparity.clone(), fastL = labels.clone(), plainD = disparity.clone(), plainL = labels.clone();
            const int filled = regionVoting(arms, parameters, fastD, fastL);
            EXPECT_EQ(filled, regionVotingReference(arms, parameters, plainD, plainL)) << oneIn << " " << ratio;
            EXPECT_GT(filled, 0) << oneIn << " " << ratio;
            if (ratio > 0.5) {
                EXPECT_LT(filled, cv::countNonZero(labels)) << oneIn;  // some votes fail
            }
            EXPECT_EQ(cv::countNonZero(fastD != plainD), 0) << oneIn << " " << ratio;
            EXPECT_EQ(cv::countNonZero(fastL != plainL), 0) << oneIn << " " << ratio;
        }
    }
}

TEST(Interpolation, OccludedFromTheLeftMismatchedTheSmaller) {
    // Nearest reliable values: 9 on the left, 5 on the right of both outliers.
    cv::Mat disparity = row16({9, 0, 0, 5});
    cv::Mat labels = (cv::Mat_<std::uint8_t>(1, 4) << kReliable, kOccluded, kMismatched, kReliable);
    interpolateOutliers(disparity, labels);
    EXPECT_EQ(disparity.at<std::int16_t>(0, 1), 9);  // occluded: the left side
    EXPECT_EQ(disparity.at<std::int16_t>(0, 2), 5);  // mismatched: min(9, 5)
    // At the left border an occluded pixel has only the right side.
    cv::Mat border = row16({0, 4});
    cv::Mat borderLabels = (cv::Mat_<std::uint8_t>(1, 2) << kOccluded, kReliable);
    interpolateOutliers(border, borderLabels);
    EXPECT_EQ(border.at<std::int16_t>(0, 0), 4);
}

TEST(DiscontinuityAdjustment, EdgePixelTakesTheCheaperSide) {
    // Row 2 ... 2 8 ... 8: pixels 9 and 10 sit on the edge. At pixel 9 the cost of 8 is lower
    // than that of its own 2, so it moves; at pixel 10 its own 8 is cheapest, so it stays.
    CostVolume v;
    v.create(12, 1, 10);
    std::fill(v.data.begin(), v.data.end(), 100);
    v.at(9, 0)[2] = 50;
    v.at(9, 0)[8] = 40;
    v.at(10, 0)[8] = 30;
    v.at(10, 0)[2] = 60;
    cv::Mat disparity = row16({2, 2, 2, 2, 2, 2, 2, 2, 2, 2, 8, 8});
    EXPECT_EQ(adjustDiscontinuities(v, disparity), 1);
    EXPECT_EQ(disparity.at<std::int16_t>(0, 9), 8);
    EXPECT_EQ(disparity.at<std::int16_t>(0, 10), 8);
    // A disparity the pixel cannot have (its right pixel would lie left of the image) is no
    // candidate, however cheap.
    cv::Mat border = row16({2, 2, 8, 8, 8, 8, 8, 8, 8, 8, 8, 8});
    v.at(1, 0)[2] = 50;
    v.at(1, 0)[8] = 0;
    EXPECT_EQ(adjustDiscontinuities(v, border), 0);
    // A smooth row (steps of one pixel) is not an edge and is left alone.
    cv::Mat smooth = row16({0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 9, 9});
    v.at(5, 0)[0] = 0;
    EXPECT_EQ(adjustDiscontinuities(v, smooth), 0);
}

TEST(Subpixel, EquiangularFit) {
    EXPECT_FLOAT_EQ(subpixelOffset(10, 0, 10), 0.0f);
    // A V of slope 20 with its apex at +0.25: costs 25, 5, 15.
    EXPECT_FLOAT_EQ(subpixelOffset(25, 5, 15), 0.25f);
    EXPECT_FLOAT_EQ(subpixelOffset(15, 5, 25), -0.25f);
    EXPECT_FLOAT_EQ(subpixelOffset(5, 5, 5), 0.0f);  // flat: no information

    CostVolume v;
    v.create(6, 1, 4);
    std::fill(v.data.begin(), v.data.end(), 100);
    std::uint16_t* c = v.at(5, 0);
    c[1] = 25;
    c[2] = 5;
    c[3] = 15;
    const cv::Mat refined = subpixelRefine(row16({-1, 0, 0, 0, 3, 2}), v, DisparityRange{0, 4});
    EXPECT_EQ(refined.at<float>(0, 0), kInvalidDisparity);
    EXPECT_FLOAT_EQ(refined.at<float>(0, 5), 2.25f);
    EXPECT_FLOAT_EQ(refined.at<float>(0, 1), 0.0f);  // d = 0 has no left neighbour: stays integer
    EXPECT_EQ(refined.at<float>(0, 4), kInvalidDisparity);  // the band's last disparity: its edge

    // The same volume as the band [7, 11): index d is disparity 7 + d, and index 0 is an edge too.
    const cv::Mat banded = subpixelRefine(row16({-1, 0, 0, 1, 3, 2}), v, DisparityRange{7, 11});
    EXPECT_EQ(banded.at<float>(0, 1), kInvalidDisparity);
    EXPECT_FLOAT_EQ(banded.at<float>(0, 3), 8.0f);
    EXPECT_EQ(banded.at<float>(0, 4), kInvalidDisparity);
    EXPECT_FLOAT_EQ(banded.at<float>(0, 5), 9.25f);
}

TEST(Subpixel, IntensityRefinementStopsAtDepthEdges) {
    // The right eye sees the texture 3.25 px to the left. The fitted map says 3 everywhere except
    // a band of columns at 9 (a nearer object): pixels whose 5x5 window reaches into the band keep
    // their fitted value, the others are refined to 3.25.
    const cv::Mat texture = test::randomImage(80, 30, CV_8UC1, 5);
    cv::Mat right;
    const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, -3.25, 0, 1, 0);  // right(x) = left(x + 3.25)
    cv::warpAffine(texture, right, shift, texture.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
    cv::Mat greyLeft, greyRight;
    texture.convertTo(greyLeft, CV_32F);
    right.convertTo(greyRight, CV_32F);
    cv::Mat disparity(texture.size(), CV_32FC1, cv::Scalar(3.0f));
    disparity.colRange(40, 44).setTo(9.0f);
    refineSubpixelByIntensity(greyLeft, greyRight, 2, 4, 0.5f, disparity);
    const int y = 15;
    for (int x = 38; x <= 45; ++x) {
        if (x >= 40 && x < 44) continue;
        EXPECT_EQ(disparity.at<float>(y, x), 3.0f) << x;  // window straddles the edge
    }
    for (int x : {20, 30, 37, 46, 60}) EXPECT_NEAR(disparity.at<float>(y, x), 3.25f, 0.1f) << x;  // 8-bit images
}

TEST(Subpixel, IntensityRefinementOptimisedMatchesReference) {
    // A smooth random texture seen 4.4 px to the left, at an awkward size and three window radii,
    // started from values with a few invalid pixels and depth edges: noisy values within 0.3 px
    // of the truth (neighbouring windows start at the same column or one apart), a slow wave of
    // ±0.6 px (windows of eight neighbouring pixels start up to three columns apart) and integers
    // (the fraction 0: every window on a column), both allowed to move by 1 px. The optimised
    // kernel's interpolation is rearranged and fused, so the two agree to float rounding: a pixel
    // whose decision sits on a threshold (converged, textureless, too far) may go the other way,
    // hardly any may.
    cv::Mat texture = test::randomImage(131, 47, CV_8UC1, 9);
    cv::GaussianBlur(texture, texture, cv::Size(0, 0), 1.2);
    cv::Mat right;
    const cv::Mat shift = (cv::Mat_<double>(2, 3) << 1, 0, -4.4, 0, 1, 0);
    cv::warpAffine(texture, right, shift, texture.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
    cv::Mat greyLeft, greyRight;
    texture.convertTo(greyLeft, CV_32F);
    right.convertTo(greyRight, CV_32F);
    enum class Start { Noisy, Wave, Integers };
    for (const Start kind : {Start::Noisy, Start::Wave, Start::Integers}) {
        cv::Mat start(texture.size(), CV_32FC1);
        cv::RNG rng(3);
        for (int y = 0; y < start.rows; ++y)
            for (int x = 0; x < start.cols; ++x) {
                const double noise = rng.uniform(-0.3, 0.3);
                double value = 4.4 + noise;
                if (kind == Start::Wave) value = 4.4 + 0.6 * std::sin(0.35 * x + 0.2 * y) + noise / 6.0;
                if (kind == Start::Integers) value = std::round(value);
                start.at<float>(y, x) = rng.uniform(0, 500) == 0 ? -1.0f : static_cast<float>(value);
            }
        start.colRange(70, 73).setTo(12.0f);
        const float maxChange = kind == Start::Noisy ? 0.5f : 1.0f;
        const int caseNumber = static_cast<int>(kind);
        for (int radius : {1, 2, 3}) {
            cv::Mat fast = start.clone(), plain = start.clone();
            refineSubpixelByIntensity(greyLeft, greyRight, radius, 2, maxChange, fast);
            refineSubpixelByIntensityReference(greyLeft, greyRight, radius, 2, maxChange, plain);
            int differing = 0, refined = 0;
            for (int y = 0; y < start.rows; ++y)
                for (int x = 0; x < start.cols; ++x) {
                    if (std::abs(fast.at<float>(y, x) - plain.at<float>(y, x)) > 1e-3f) ++differing;
                    if (plain.at<float>(y, x) != start.at<float>(y, x)) ++refined;
                }
            // The comparison means something.
            EXPECT_GT(refined, static_cast<int>(start.total() / 2)) << caseNumber << " " << radius;
            EXPECT_LE(differing, static_cast<int>(start.total() / 1000)) << caseNumber << " " << radius;
        }
    }
}

TEST(ImpulseFilter, RepairsOnlyImpulses) {
    // A vertical ramp (a clean structure that must survive) with one white and one black impulse.
    cv::Mat bgr(7, 7, CV_8UC3);
    for (int y = 0; y < 7; ++y) bgr.row(y).setTo(cv::Scalar::all(100 + 10 * y));
    bgr.at<cv::Vec3b>(2, 2) = {255, 255, 255};
    bgr.at<cv::Vec3b>(4, 5) = {0, 0, 0};
    cv::Mat grey;
    cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
    const cv::Mat clean = bgr.clone();
    EXPECT_EQ(removeImpulses(bgr, grey, 40), 2);
    EXPECT_EQ(bgr.at<cv::Vec3b>(2, 2), cv::Vec3b::all(120));
    EXPECT_EQ(bgr.at<cv::Vec3b>(4, 5), cv::Vec3b::all(140));
    EXPECT_EQ(grey.at<std::uint8_t>(2, 2), 120);
    EXPECT_EQ(bgr.at<cv::Vec3b>(3, 3), clean.at<cv::Vec3b>(3, 3));  // the ramp is untouched
    EXPECT_EQ(removeImpulses(bgr, grey, 40), 0);
}

TEST(ImpulseFilter, IsolatedRailPixelsNeedLessContrast) {
    // A bright flat wall: a white impulse on it is only 35 levels from its median, below the
    // general threshold; a two-pixel highlight at 255 is a plateau, not an impulse.
    cv::Mat bgr(9, 9, CV_8UC3, cv::Scalar::all(220));
    bgr.at<cv::Vec3b>(2, 2) = {255, 255, 255};
    bgr.at<cv::Vec3b>(6, 5) = {255, 255, 255};
    bgr.at<cv::Vec3b>(6, 6) = {255, 255, 255};
    cv::Mat grey;
    cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
    cv::Mat bgrCopy = bgr.clone(), greyCopy = grey.clone();
    EXPECT_EQ(removeImpulses(bgrCopy, greyCopy, 40), 0);
    EXPECT_EQ(removeImpulses(bgr, grey, 40, 10), 1);
    EXPECT_EQ(bgr.at<cv::Vec3b>(2, 2), cv::Vec3b::all(220));
    EXPECT_EQ(bgr.at<cv::Vec3b>(6, 5), cv::Vec3b::all(255));
    EXPECT_EQ(bgr.at<cv::Vec3b>(6, 6), cv::Vec3b::all(255));
}

}  // namespace
}  // namespace icewatch::stereo::detail
