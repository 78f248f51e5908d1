#include "core/calib/chessboard_calibration.hpp"

#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/common/error.hpp"
#include "tests/support/test_paths.hpp"

namespace icewatch::calib {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The pinhole pair the synthetic views are rendered with: two slightly different cameras with
// lens distortion, the right one 60 mm to the right and a little rotated.
struct TruePair {
    cv::Size imageSize{640, 480};
    cv::Mat M1 = (cv::Mat_<double>(3, 3) << 400, 0, 322.5, 0, 400, 236.0, 0, 0, 1);
    cv::Mat D1 = (cv::Mat_<double>(1, 5) << -0.08, 0.02, 0.0004, -0.0003, 0);
    cv::Mat M2 = (cv::Mat_<double>(3, 3) << 404, 0, 317.0, 0, 404, 243.5, 0, 0, 1);
    cv::Mat D2 = (cv::Mat_<double>(1, 5) << -0.06, 0.015, -0.0002, 0.0005, 0);
    cv::Mat rvec = (cv::Mat_<double>(3, 1) << 0.004, -0.01, 0.003);
    cv::Mat T = (cv::Mat_<double>(3, 1) << -60.0, 0.4, -0.3);
};

// Draws a chessboard seen by camera (M, D) at pose (rvec, tvec): white board with a one-square
// margin, black squares, every edge split into short segments so the lens distortion bends it, a
// little sensor noise. The polygons are anti-aliased by area coverage: filled at 8x resolution and
// averaged down. (cv::LINE_AA polygons are about a pixel too fat, which moves the saddle where two
// black squares meet and would bias every corner.)
cv::Mat renderBoard(const ChessboardSpec& board, cv::Size imageSize, const cv::Mat& M, const cv::Mat& D,
                    const cv::Mat& rvec, const cv::Mat& tvec, uint64_t noiseSeed) {
    constexpr int kSegments = 8;
    constexpr int kSupersample = 8;
    constexpr int kShift = 4;
    const double s = board.squareMm;
    auto polygon = [&](double x0, double y0, double x1, double y1) {
        std::vector<cv::Point3d> corners3d{{x0, y0, 0}, {x1, y0, 0}, {x1, y1, 0}, {x0, y1, 0}};
        std::vector<cv::Point3d> outline;
        for (int e = 0; e < 4; ++e) {
            const cv::Point3d a = corners3d[e], b = corners3d[(e + 1) % 4];
            for (int k = 0; k < kSegments; ++k) {
                outline.push_back(a + (b - a) * (static_cast<double>(k) / kSegments));
            }
        }
        std::vector<cv::Point2d> projected;
        cv::projectPoints(outline, rvec, tvec, M, D, projected);
        std::vector<cv::Point> fixedPoint;
        for (const cv::Point2d& p : projected) {
            // Pixel centres sit at integers in both grids: x_fine = (x + 0.5) * k - 0.5.
            const cv::Point2d fine = (p + cv::Point2d(0.5, 0.5)) * kSupersample - cv::Point2d(0.5, 0.5);
            fixedPoint.emplace_back(cvRound(fine.x * (1 << kShift)), cvRound(fine.y * (1 << kShift)));
        }
        return std::vector<std::vector<cv::Point>>{fixedPoint};
    };
    cv::Mat fine(imageSize * kSupersample, CV_8UC1, cv::Scalar(90));
    const int cols = board.innerCorners.width + 1, rows = board.innerCorners.height + 1;
    cv::fillPoly(fine, polygon(-2 * s, -2 * s, cols * s, rows * s), cv::Scalar(235), cv::LINE_8, kShift);
    for (int r = 0; r < rows; ++r) {
        for (int c = 0; c < cols; ++c) {
            if ((r + c) % 2 == 0) {
                const double x0 = (c - 1) * s, y0 = (r - 1) * s;
                cv::fillPoly(fine, polygon(x0, y0, x0 + s, y0 + s), cv::Scalar(20), cv::LINE_8, kShift);
            }
        }
    }
    cv::Mat image;
    cv::resize(fine, image, imageSize, 0, 0, cv::INTER_AREA);
    cv::Mat noise(imageSize, CV_16SC1);
    cv::RNG rng(noiseSeed);
    rng.fill(noise, cv::RNG::NORMAL, 0, 2.0);
    cv::Mat noisy;
    cv::add(image, noise, noisy, cv::noArray(), CV_8UC1);
    return noisy;
}

// A dozen poses spread over the field of view, tilted up to ~30° both ways, 450-750 mm away.
std::vector<std::pair<cv::Vec3d, cv::Vec3d>> boardPoses() {
    std::vector<std::pair<cv::Vec3d, cv::Vec3d>> poses;
    const double deg = kPi / 180.0;
    const double tilts[][3] = {{0, 0, 0},     {25, 0, 5},   {-25, 0, -5},  {0, 28, 0},   {0, -28, 3},  {20, 20, 10},
                               {-20, 20, -8}, {20, -22, 0}, {-18, -20, 6}, {10, 10, 30}, {-12, 8, -25}, {30, -8, 2}};
    const double centres[][3] = {{0, 0, 600},    {-80, -40, 550}, {90, 50, 620},  {-60, 60, 700}, {70, -50, 650},
                                 {0, 40, 480},   {-100, 0, 720},  {100, 20, 560}, {30, -70, 600}, {-40, 30, 520},
                                 {60, 70, 680},  {-20, -60, 750}};
    for (int i = 0; i < 12; ++i) {
        poses.emplace_back(cv::Vec3d(tilts[i][0] * deg, tilts[i][1] * deg, tilts[i][2] * deg),
                           cv::Vec3d(centres[i][0], centres[i][1], centres[i][2]));
    }
    return poses;
}

TEST(ChessboardCalibration, OpenCvSampleSetMeetsTargets) {
    const auto dir = test::sharedData() / "calibration" / "opencv-chessboard-9x6";
    ASSERT_TRUE(std::filesystem::is_directory(dir)) << dir;
    ChessboardCalibrator calibrator({{9, 6}, 1.0});
    std::vector<StereoPair> pairs;
    for (const char* nn : {"01", "02", "03", "04", "05", "06", "07", "08", "09", "11", "12", "13", "14"}) {
        StereoPair pair{cv::imread((dir / ("left" + std::string(nn) + ".jpg")).string(), cv::IMREAD_GRAYSCALE),
                        cv::imread((dir / ("right" + std::string(nn) + ".jpg")).string(), cv::IMREAD_GRAYSCALE)};
        ASSERT_FALSE(pair.left.empty() || pair.right.empty()) << nn;
        calibrator.addView(nn, pair);
        pairs.push_back(pair);
    }
    const ChessboardCalibrationResult r = calibrator.calibrate();
    EXPECT_LE(r.rmsPx, 0.5);
    EXPECT_LE(r.epipolarPx, 0.5);
    EXPECT_GE(r.used.size(), 10u);
    EXPECT_EQ(r.used.size() + r.skipped.size(), 13u);
    EXPECT_EQ(r.calibration.imageSize, cv::Size(640, 480));
    // The sample rig's eyes sit side by side: the baseline is mostly along x.
    EXPECT_GT(std::abs(r.calibration.T.at<double>(0)), 0.9 * r.calibration.baselineMm());

    // The Rectifier's images agree with the corner maths: corners found again in rectified pairs
    // lie on the same rows in both eyes.
    const Rectifier rectifier(r.calibration);
    double sumDy = 0;
    int count = 0;
    for (size_t i = 0; i < pairs.size(); i += 4) {
        const StereoPair rectified = rectifier.rectify(pairs[i]);
        const auto left = findChessboardCornersSubPix(rectified.left, {9, 6});
        auto right = findChessboardCornersSubPix(rectified.right, {9, 6});
        ASSERT_EQ(left.size(), 54u) << i;
        ASSERT_EQ(right.size(), 54u) << i;
        if ((left.back() - left.front()).dot(right.back() - right.front()) < 0) {
            std::reverse(right.begin(), right.end());
        }
        for (size_t k = 0; k < left.size(); ++k) {
            sumDy += std::abs(left[k].y - right[k].y);
            ++count;
        }
    }
    EXPECT_LE(sumDy / count, 0.5);
    std::cout << "opencv set: rectified images, mean |dy| " << sumDy / count << " px\n";
    std::cout << "opencv set: rms_px " << r.rmsPx << " epipolar_px " << r.epipolarPx << " max " << r.maxEpipolarPx
              << " used " << r.used.size() << " skipped " << r.skipped.size() << "\n";
}

TEST(ChessboardCalibration, SyntheticRoundTripRecoversFocalAndBaseline) {
    const TruePair truth;
    const ChessboardSpec board{{9, 6}, 30.0};
    cv::Mat rotation;
    cv::Rodrigues(truth.rvec, rotation);

    ChessboardCalibrator calibrator(board);
    const cv::Vec3d boardCentre(4 * board.squareMm, 2.5 * board.squareMm, 0);
    uint64_t seed = 1;
    for (const auto& [tilt, centre] : boardPoses()) {
        cv::Mat boardRotation;
        cv::Rodrigues(cv::Mat(tilt), boardRotation);
        const cv::Mat tvecLeft = cv::Mat(centre) - boardRotation * cv::Mat(boardCentre);
        cv::Mat rvecRight, rotationRight = rotation * boardRotation;
        cv::Rodrigues(rotationRight, rvecRight);
        const cv::Mat tvecRight = rotation * tvecLeft + truth.T;
        StereoPair pair{renderBoard(board, truth.imageSize, truth.M1, truth.D1, cv::Mat(tilt), tvecLeft, seed),
                        renderBoard(board, truth.imageSize, truth.M2, truth.D2, rvecRight, tvecRight, seed + 1)};
        seed += 2;
        EXPECT_TRUE(calibrator.addView("pose" + std::to_string(seed / 2), pair));
    }
    // A view where the right eye missed the board is skipped, by name.
    StereoPair missing{renderBoard(board, truth.imageSize, truth.M1, truth.D1, cv::Mat(cv::Vec3d(0, 0, 0)),
                                   cv::Mat(cv::Vec3d(-100, -60, 600)), 99),
                       cv::Mat(truth.imageSize, CV_8UC1, cv::Scalar(128))};
    EXPECT_FALSE(calibrator.addView("blank-right", missing));

    const ChessboardCalibrationResult r = calibrator.calibrate();
    ASSERT_EQ(r.skipped.size(), 1u);
    EXPECT_EQ(r.skipped[0].name, "blank-right");
    EXPECT_NE(r.skipped[0].reason.find("right eye"), std::string::npos) << r.skipped[0].reason;
    EXPECT_EQ(r.used.size(), 12u);

    const StereoCalibration& c = r.calibration;
    const double f1Error = std::abs(c.M1.at<double>(0, 0) / truth.M1.at<double>(0, 0) - 1);
    const double f2Error = std::abs(c.M2.at<double>(1, 1) / truth.M2.at<double>(1, 1) - 1);
    const double baselineError = std::abs(c.baselineMm() / cv::norm(truth.T) - 1);
    EXPECT_LT(f1Error, 0.01);
    EXPECT_LT(f2Error, 0.01);
    EXPECT_LT(baselineError, 0.01);
    EXPECT_LT(r.rmsPx, 0.3);
    EXPECT_LT(r.epipolarPx, 0.1);
    std::cout << "synthetic: f1 error " << f1Error * 100 << " %, f2 error " << f2Error * 100 << " %, baseline "
              << c.baselineMm() << " mm (error " << baselineError * 100 << " %), rms_px " << r.rmsPx
              << ", epipolar_px " << r.epipolarPx << "\n";
}

// Large frames are searched at a reduced scale and refined at full resolution: the corners must
// land where they do at full scale.
TEST(ChessboardCalibration, LargeImagesFindTheSameCorners) {
    const cv::Mat small = cv::imread(
        (test::sharedData() / "calibration" / "opencv-chessboard-9x6" / "left01.jpg").string(), cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(small.empty());
    constexpr double kScale = 3.0;
    cv::Mat large;
    cv::resize(small, large, cv::Size(), kScale, kScale, cv::INTER_CUBIC);
    const auto reference = findChessboardCornersSubPix(small, {9, 6});
    const auto found = findChessboardCornersSubPix(large, {9, 6});
    ASSERT_EQ(reference.size(), 54u);
    ASSERT_EQ(found.size(), 54u);
    double worst = 0, sum = 0;
    cv::Point2d bias(0, 0);
    for (size_t i = 0; i < found.size(); ++i) {
        // Pixel centres at integers in both: x_large = (x_small + 0.5) * k - 0.5.
        const cv::Point2f expected((reference[i].x + 0.5f) * kScale - 0.5f, (reference[i].y + 0.5f) * kScale - 0.5f);
        const cv::Point2d difference = cv::Point2d(found[i] - expected) / kScale;
        worst = std::max(worst, cv::norm(difference));
        sum += cv::norm(difference);
        bias += difference / static_cast<double>(found.size());
    }
    // In pixels of the small image. The two refinements use different windows on differently
    // sampled images, so single corners differ by ~0.1 px; a wrong mapping back from the reduced
    // scale would shift them all alike.
    EXPECT_LT(cv::norm(bias), 0.05);
    EXPECT_LT(sum / found.size(), 0.15);
    EXPECT_LT(worst, 0.3);
}

TEST(ChessboardCalibration, TooFewViewsNamesTheSkippedOnes) {
    ChessboardCalibrator calibrator({{9, 6}, 25.0});
    const cv::Mat grey(120, 160, CV_8UC1, cv::Scalar(128));
    EXPECT_FALSE(calibrator.addView("frame-a", {grey, grey}));
    try {
        calibrator.calibrate();
        FAIL() << "no usable view must not calibrate";
    } catch (const InvalidInput& e) {
        EXPECT_NE(std::string(e.what()).find("frame-a: chessboard 9x6 not found in either eye"), std::string::npos)
            << e.what();
    }
    // Views from another camera mode cannot be mixed in.
    const cv::Mat other(100, 160, CV_8UC1, cv::Scalar(128));
    EXPECT_THROW(calibrator.addView("frame-b", {other, other}), InvalidInput);
    EXPECT_THROW(ChessboardCalibrator({{1, 6}, 25.0}), InvalidInput);
    EXPECT_THROW(ChessboardCalibrator({{9, 6}, 0.0}), InvalidInput);
}

}  // namespace
}  // namespace icewatch::calib
