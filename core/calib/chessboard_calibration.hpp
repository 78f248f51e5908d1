#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/calib/stereo_calibration.hpp"
#include "core/common/side_by_side.hpp"

namespace icewatch::calib {

// A printed chessboard: inner corners counted as cv::findChessboardCorners counts them (columns x
// rows, "9x6") and the side of one square in millimetres, which sets the unit of T.
struct ChessboardSpec {
    cv::Size innerCorners{9, 6};
    double squareMm = 1.0;
};

// Fewer views than this cannot pin down two cameras' intrinsics and their relative pose.
inline constexpr int kMinChessboardViews = 3;

// A view that did not contribute, and why (a person reads this to re-take it).
struct SkippedView {
    std::string name;
    std::string reason;
};

// The per-view RMS reprojection error of each eye, so a person can spot a bad capture.
struct ViewError {
    std::string name;
    double leftRmsPx = 0;
    double rightRmsPx = 0;
};

struct ChessboardCalibrationResult {
    StereoCalibration calibration;  // R1 R2 P1 P2 Q derived
    double rmsPx = 0;               // cv::stereoCalibrate's RMS reprojection error over both eyes
    double epipolarPx = 0;          // mean |y_left - y_right| of the matched corners after rectification
    double maxEpipolarPx = 0;       // the worst corner of that
    std::vector<ViewError> used;    // in the order the views were added
    std::vector<SkippedView> skipped;
};

// Sub-pixel chessboard corners in one eye (findChessboardCorners, then cornerSubPix with a window
// sized to the squares), or an empty vector when the whole board is not found. Large images are
// searched at a reduced scale and refined at full resolution. Accepts 8-bit grey or BGR.
std::vector<cv::Point2f> findChessboardCornersSubPix(const cv::Mat& eye, cv::Size innerCorners);

// Mean and maximum |y_left - y_right| of matched image points after rectifying them with the
// calibration's R1 P1 / R2 P2: zero for a perfect calibration.
struct EpipolarError {
    double meanPx = 0;
    double maxPx = 0;
};
EpipolarError epipolarError(const StereoCalibration& calibration,
                            const std::vector<std::vector<cv::Point2f>>& leftPoints,
                            const std::vector<std::vector<cv::Point2f>>& rightPoints);

// Chessboard stereo calibration. Views are added one at a time and only their corners are kept,
// so a long recording at full resolution does not have to sit in memory.
class ChessboardCalibrator {
public:
    // Throws InvalidInput for a board with fewer than 2x2 inner corners or a non-positive square.
    explicit ChessboardCalibrator(ChessboardSpec board);

    // Looks for the board in both eyes. Returns false, and records the view as skipped with the
    // reason, when it is not found in both. Throws InvalidInput when the eyes' size differs from
    // the first view's (all views must come from one camera mode).
    bool addView(const std::string& name, const StereoPair& pair);

    // Per-eye calibrateCamera, then stereoCalibrate refining both cameras and their pose, then
    // stereoRectify. Throws InvalidInput (naming the skipped views) with fewer than
    // kMinChessboardViews usable views.
    ChessboardCalibrationResult calibrate() const;

    int viewsUsed() const { return static_cast<int>(leftCorners_.size()); }
    const std::vector<SkippedView>& skipped() const { return skipped_; }

private:
    ChessboardSpec board_;
    cv::Size imageSize_;
    std::vector<std::string> names_;
    std::vector<std::vector<cv::Point2f>> leftCorners_, rightCorners_;
    std::vector<SkippedView> skipped_;
};

}  // namespace icewatch::calib
