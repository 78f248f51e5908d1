#pragma once

#include <filesystem>
#include <string>

#include <opencv2/core.hpp>

#include "core/common/side_by_side.hpp"

namespace icewatch::calib {

// A calibrated stereo pair in the names of OpenCV's stereo_calib sample. All matrices CV_64F.
// M1/M2: 3×3 camera matrices; D1/D2: 1×N distortion (N = 4, 5, 8, 12 or 14); R: 3×3 rotation and
// T: 3×1 translation of the right camera relative to the left, T in millimetres.
// R1 R2 P1 P2 Q come from cv::stereoRectify (zero-disparity principal points, alpha 0).
struct StereoCalibration {
    cv::Mat M1, D1, M2, D2, R, T;
    cv::Size imageSize;  // per eye
    cv::Mat R1, R2, P1, P2, Q;

    double baselineMm() const;        // |T|
    double rectifiedFocalPx() const;  // P1(0,0): the f of Z = f·B/d after rectification
};

// Computes R1 R2 P1 P2 Q from M D R T and the image size (cv::stereoRectify).
void deriveRectification(StereoCalibration& calibration);

// An ideal HBVCAM: pinhole, no distortion, principal point at the centre, square pixels, the
// right eye baselineMm to the right of the left one, f from the horizontal field of view.
StereoCalibration nominalCalibration(cv::Size eyeSize, double horizontalFovDeg, double baselineMm);

// Reads and validates a calibration file (OpenCV FileStorage YAML, parsed with yaml-cpp: OpenCV's
// own parser can hang on a malformed file). Every entry's shape and values are checked (positive
// focal lengths, a rotation that is one, a non-zero baseline, a positive image size); R1 R2 P1 P2
// Q are derived when absent. Throws Error(kExitDataErr or kExitNoInput) naming the file and the
// entry, whatever the bytes (a fuzz target holds it to that).
StereoCalibration loadCalibration(const std::filesystem::path& path);

// The same from the file's text (without OpenCV's "%YAML:1.0" line); where names it in messages.
StereoCalibration parseCalibration(const std::string& text, const std::string& where);

// Writes all entries (deriving the rectification first if missing). Throws Error(kExitCantCreate).
void saveCalibration(const std::filesystem::path& path, const StereoCalibration& calibration);
// The same with a comment at the top of the file (how it was made: the command, the figures).
void saveCalibration(const std::filesystem::path& path, const StereoCalibration& calibration,
                     const std::string& comment);

// Checks a calibration held in memory the same way loadCalibration does; `where` names it in
// messages. Throws Error(kExitDataErr).
void validateCalibration(const StereoCalibration& calibration, const std::string& where);

// Throws InvalidInput when a side-by-side frame of frameSize does not hold two eyes of the
// calibration's imageSize; the message names both sizes and calibrationName (the file).
void checkFrameSize(const StereoCalibration& calibration, cv::Size frameSize, const std::string& calibrationName);

// Rectifies pairs for one calibration: the fixed-point maps are computed once in the constructor
// and every pair costs two remaps.
class Rectifier {
public:
    explicit Rectifier(const StereoCalibration& calibration);

    // Throws InvalidInput when an eye's size differs from the calibration's.
    StereoPair rectify(const StereoPair& pair) const;
    // Only the rectified pixels inside `box` (the same box in both eyes): the result is box-sized,
    // equal to that part of the whole rectification. The box must lie inside the maps kept (focus).
    StereoPair rectify(const StereoPair& pair, const cv::Rect& box) const;
    // The left eye alone, as rectify() would give it (an image that goes with the left eye: its noise).
    cv::Mat rectifyLeft(const cv::Mat& left, const cv::Rect& box) const;
    cv::Size imageSize() const { return imageSize_; }

    // Keeps the maps of `box` alone and gives the rest back: a caller that rectifies one region
    // every cycle reads a part of them (25 MB of maps at 1920x1080 an eye). A box outside the part
    // kept has the whole maps built again first (tens of milliseconds). The rectified pixels are
    // the same either way.
    void focus(const cv::Rect& box);
    cv::Rect mapped() const { return mapped_; }

private:
    // Throws InvalidInput when an eye does not have the calibration's size or `box` lies outside the maps kept.
    void checkInputs(cv::Size left, cv::Size right, const cv::Rect& box) const;
    void buildMaps();

    StereoCalibration calibration_;  // with its rectification derived
    cv::Size imageSize_;
    cv::Rect mapped_;  // the part of the image the maps cover
    cv::Mat leftMap1_, leftMap2_, rightMap1_, rightMap2_;
};

}  // namespace icewatch::calib
