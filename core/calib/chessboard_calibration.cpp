// Chessboard stereo calibration, the commissioning step of every box.
//
// The recipe is OpenCV's stereo_calib sample made robust for unattended use: corners are found in
// each eye (findChessboardCorners + cornerSubPix), a view counts only when the whole board is seen
// by both eyes, each camera is first calibrated on its own (so stereoCalibrate starts from good
// intrinsics instead of a guess) and stereoCalibrate then refines both cameras and their relative
// pose together. The figure that matters downstream is not the reprojection RMS but how well
// rectified rows line up (the matcher searches along rows only), so the result carries the mean
// |y_left - y_right| of every matched corner after rectification.
#include "core/calib/chessboard_calibration.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "core/common/error.hpp"

namespace icewatch::calib {

namespace {

// Above this many pixels on the long side the board is searched on a reduced copy: the search cost
// grows with the image while the corners' positions are refined at full resolution anyway.
constexpr int kDetectionLongSidePx = 1280;

// Radial k1 k2 plus tangential p1 p2; k3 fixed at zero. A dozen views of a flat board hardly
// constrain k3: freeing it lowered the RMS of the OpenCV sample set by 0.0003 px only and raised
// the epipolar error of the synthetic round trip (0.071 against 0.063 px).
constexpr int kDistortionFlags = cv::CALIB_FIX_K3;

std::string sizeText(cv::Size s) { return std::to_string(s.width) + "x" + std::to_string(s.height); }

cv::Mat toGrey(const cv::Mat& image) {
    if (image.channels() == 1) {
        return image;
    }
    cv::Mat grey;
    cv::cvtColor(image, grey, image.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
    return grey;
}

// The smallest distance between neighbouring corners along rows and columns: the size of one
// square in pixels where the board is seen most obliquely.
double minCornerSpacingPx(const std::vector<cv::Point2f>& corners, cv::Size inner) {
    double spacing = std::numeric_limits<double>::max();
    for (int row = 0; row < inner.height; ++row) {
        for (int col = 0; col < inner.width; ++col) {
            const cv::Point2f& p = corners[row * inner.width + col];
            if (col + 1 < inner.width) {
                spacing = std::min(spacing, cv::norm(corners[row * inner.width + col + 1] - p));
            }
            if (row + 1 < inner.height) {
                spacing = std::min(spacing, cv::norm(corners[(row + 1) * inner.width + col] - p));
            }
        }
    }
    return spacing;
}

bool detect(const cv::Mat& grey, cv::Size inner, std::vector<cv::Point2f>& corners) {
    const int flags = cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE;
    const int longSide = std::max(grey.cols, grey.rows);
    if (longSide > kDetectionLongSidePx) {
        const double scale = static_cast<double>(kDetectionLongSidePx) / longSide;
        cv::Mat small;
        cv::resize(grey, small, cv::Size(), scale, scale, cv::INTER_AREA);
        if (cv::findChessboardCorners(small, inner, corners, flags)) {
            for (cv::Point2f& p : corners) {
                p = cv::Point2f(static_cast<float>((p.x + 0.5) / scale - 0.5), static_cast<float>((p.y + 0.5) / scale - 0.5));
            }
            return true;
        }
        // A small, distant board may only be found at full resolution.
    }
    return cv::findChessboardCorners(grey, inner, corners, flags);
}

std::vector<cv::Point3f> boardPoints(const ChessboardSpec& board) {
    std::vector<cv::Point3f> points;
    points.reserve(static_cast<size_t>(board.innerCorners.area()));
    for (int row = 0; row < board.innerCorners.height; ++row) {
        for (int col = 0; col < board.innerCorners.width; ++col) {
            points.emplace_back(static_cast<float>(col * board.squareMm), static_cast<float>(row * board.squareMm), 0.f);
        }
    }
    return points;
}

}  // namespace

std::vector<cv::Point2f> findChessboardCornersSubPix(const cv::Mat& eye, cv::Size innerCorners) {
    if (eye.empty() || eye.depth() != CV_8U) {
        throw InvalidInput("chessboard detection needs a non-empty 8-bit image");
    }
    const cv::Mat grey = toGrey(eye);
    std::vector<cv::Point2f> corners;
    if (!detect(grey, innerCorners, corners)) {
        return {};
    }
    // The refinement window must stay well inside one square, or the board's outer edge and the
    // neighbouring corners pull on the estimate: with a radius of 0.4 square some corners of the
    // OpenCV sample set jumped by up to 4 px; at 0.3 none moved by more than 0.7 px from its
    // epipolar line. 11 px (the sample's) is plenty for large squares.
    const int halfWindow = std::clamp(static_cast<int>(minCornerSpacingPx(corners, innerCorners) * 0.3), 2, 11);
    cv::cornerSubPix(grey, corners, cv::Size(halfWindow, halfWindow), cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100, 1e-3));
    return corners;
}

EpipolarError epipolarError(const StereoCalibration& calibration,
                            const std::vector<std::vector<cv::Point2f>>& leftPoints,
                            const std::vector<std::vector<cv::Point2f>>& rightPoints) {
    if (leftPoints.size() != rightPoints.size()) {
        throw InvalidInput("epipolar error needs as many left views as right views");
    }
    EpipolarError error;
    size_t count = 0;
    std::vector<cv::Point2f> left, right;
    for (size_t view = 0; view < leftPoints.size(); ++view) {
        if (leftPoints[view].size() != rightPoints[view].size()) {
            throw InvalidInput("epipolar error needs matched points: view " + std::to_string(view) +
                               " has different counts");
        }
        if (leftPoints[view].empty()) {
            continue;
        }
        cv::undistortPoints(leftPoints[view], left, calibration.M1, calibration.D1, calibration.R1, calibration.P1);
        cv::undistortPoints(rightPoints[view], right, calibration.M2, calibration.D2, calibration.R2, calibration.P2);
        for (size_t i = 0; i < left.size(); ++i) {
            const double dy = std::abs(static_cast<double>(left[i].y) - right[i].y);
            error.meanPx += dy;
            error.maxPx = std::max(error.maxPx, dy);
        }
        count += left.size();
    }
    if (count > 0) {
        error.meanPx /= static_cast<double>(count);
    }
    return error;
}

ChessboardCalibrator::ChessboardCalibrator(ChessboardSpec board) : board_(board) {
    if (board_.innerCorners.width < 2 || board_.innerCorners.height < 2) {
        throw InvalidInput("chessboard must have at least 2x2 inner corners, got " + sizeText(board_.innerCorners));
    }
    if (!(board_.squareMm > 0) || !std::isfinite(board_.squareMm)) {
        throw InvalidInput("chessboard square size must be a positive number of millimetres");
    }
}

bool ChessboardCalibrator::addView(const std::string& name, const StereoPair& pair) {
    if (pair.left.empty() || pair.right.empty() || pair.left.size() != pair.right.size()) {
        throw InvalidInput(name + ": a view needs two non-empty eyes of the same size");
    }
    if (imageSize_.area() == 0) {
        imageSize_ = pair.left.size();
    } else if (pair.left.size() != imageSize_) {
        throw InvalidInput(name + ": eye size " + sizeText(pair.left.size()) + " differs from the first view's " +
                           sizeText(imageSize_) + " (all views must come from one camera mode)");
    }
    std::vector<cv::Point2f> left = findChessboardCornersSubPix(pair.left, board_.innerCorners);
    std::vector<cv::Point2f> right = findChessboardCornersSubPix(pair.right, board_.innerCorners);
    if (left.empty() || right.empty()) {
        const std::string where = left.empty() && right.empty() ? "either eye" : left.empty() ? "the left eye" : "the right eye";
        skipped_.push_back({name, "chessboard " + sizeText(board_.innerCorners) + " not found in " + where});
        return false;
    }
    // findChessboardCorners may start from either end of a board whose pattern is symmetric; the
    // two eyes see the board almost alike, so their corner runs must point the same way.
    const cv::Point2f leftRun = left.back() - left.front();
    const cv::Point2f rightRun = right.back() - right.front();
    if (leftRun.dot(rightRun) < 0) {
        std::reverse(right.begin(), right.end());
    }
    names_.push_back(name);
    leftCorners_.push_back(std::move(left));
    rightCorners_.push_back(std::move(right));
    return true;
}

ChessboardCalibrationResult ChessboardCalibrator::calibrate() const {
    if (viewsUsed() < kMinChessboardViews) {
        std::string message = "chessboard calibration needs at least " + std::to_string(kMinChessboardViews) +
                              " views with the board in both eyes, got " + std::to_string(viewsUsed());
        for (const SkippedView& s : skipped_) {
            message += "; " + s.name + ": " + s.reason;
        }
        throw InvalidInput(message);
    }
    const std::vector<std::vector<cv::Point3f>> objectPoints(leftCorners_.size(), boardPoints(board_));
    const cv::TermCriteria criteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 200, 1e-9);

    StereoCalibration c;
    c.imageSize = imageSize_;
    ChessboardCalibrationResult result;
    cv::Mat perViewErrors;
    try {
        std::vector<cv::Mat> rvecs, tvecs;
        cv::calibrateCamera(objectPoints, leftCorners_, imageSize_, c.M1, c.D1, rvecs, tvecs, kDistortionFlags,
                            criteria);
        cv::calibrateCamera(objectPoints, rightCorners_, imageSize_, c.M2, c.D2, rvecs, tvecs, kDistortionFlags,
                            criteria);
        cv::Mat essential, fundamental;
        result.rmsPx = cv::stereoCalibrate(objectPoints, leftCorners_, rightCorners_, c.M1, c.D1, c.M2, c.D2,
                                           imageSize_, c.R, c.T, essential, fundamental, perViewErrors,
                                           cv::CALIB_USE_INTRINSIC_GUESS | kDistortionFlags, criteria);
        c.D1 = c.D1.reshape(1, 1);
        c.D2 = c.D2.reshape(1, 1);
        c.T = c.T.reshape(1, 3);
        deriveRectification(c);
    } catch (const cv::Exception& e) {
        // Degenerate views (all alike, all fronto-parallel) make the solvers give up.
        throw InvalidInput("chessboard calibration failed on these views (" + e.err +
                           "): show the board at more varied positions and tilts");
    }
    validateCalibration(c, "chessboard calibration");

    const EpipolarError epipolar = epipolarError(c, leftCorners_, rightCorners_);
    result.epipolarPx = epipolar.meanPx;
    result.maxEpipolarPx = epipolar.maxPx;
    for (size_t i = 0; i < names_.size(); ++i) {
        result.used.push_back({names_[i], perViewErrors.at<double>(static_cast<int>(i), 0),
                               perViewErrors.at<double>(static_cast<int>(i), 1)});
    }
    result.skipped = skipped_;
    result.calibration = std::move(c);
    return result;
}

}  // namespace icewatch::calib
