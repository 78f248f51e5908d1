// Calibration data: the file format (OpenCV FileStorage YAML with the stereo_calib sample's names,
// read with yaml-cpp),
// its validation, the nominal HBVCAM model and rectification maps.
#include "core/calib/stereo_calibration.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <yaml-cpp/yaml.h>

#include "core/common/error.hpp"

namespace icewatch::calib {

namespace {

constexpr double kPi = 3.14159265358979323846;
// Far above any sensor this product meets; a larger value is a corrupt file, not a camera.
constexpr int kMaxEyeSidePx = 16384;
// The largest matrix a calibration holds is 4x4 (Q) or 1x14 (D); anything much bigger is corruption.
constexpr int kMaxMatrixSide = 16;

std::string sizeText(cv::Size s) { return std::to_string(s.width) + "x" + std::to_string(s.height); }

[[noreturn]] void failEntry(const std::string& where, const std::string& entry, const std::string& what) {
    throw Error(kExitDataErr, where + ": " + entry + ": " + what);
}

void checkMatrix(const cv::Mat& m, const std::string& where, const std::string& entry, int rows, int cols) {
    if (m.empty()) {
        failEntry(where, entry, "missing");
    }
    if (m.rows != rows || m.cols != cols) {
        failEntry(where, entry, "must be " + std::to_string(rows) + "x" + std::to_string(cols) + ", got " +
                                    std::to_string(m.rows) + "x" + std::to_string(m.cols));
    }
    if (m.type() != CV_64FC1) {
        failEntry(where, entry, "must hold double-precision numbers");
    }
    if (!cv::checkRange(m)) {
        failEntry(where, entry, "holds a value that is not a finite number");
    }
}

void checkCameraMatrix(const cv::Mat& m, const std::string& where, const std::string& entry, cv::Size size) {
    checkMatrix(m, where, entry, 3, 3);
    const double fx = m.at<double>(0, 0), fy = m.at<double>(1, 1);
    if (fx <= 0 || fy <= 0) {
        failEntry(where, entry, "focal lengths must be positive");
    }
    if (m.at<double>(1, 0) != 0 || m.at<double>(2, 0) != 0 || m.at<double>(2, 1) != 0 ||
        m.at<double>(2, 2) != 1) {
        failEntry(where, entry, "is not a camera matrix (last row must be 0 0 1, lower part zero)");
    }
    const double cx = m.at<double>(0, 2), cy = m.at<double>(1, 2);
    if (cx < 0 || cx > size.width || cy < 0 || cy > size.height) {
        failEntry(where, entry, "principal point lies outside the image");
    }
}

void checkRotation(const cv::Mat& r, const std::string& where, const std::string& entry) {
    checkMatrix(r, where, entry, 3, 3);
    const cv::Mat shouldBeIdentity = r * r.t();
    if (cv::norm(shouldBeIdentity, cv::Mat::eye(3, 3, CV_64F), cv::NORM_INF) > 1e-6 || cv::determinant(r) < 0) {
        failEntry(where, entry, "is not a rotation matrix");
    }
}

// A rectified camera's 3x4 projection [f 0 cx tx; 0 f cy 0; 0 0 1 0].
void checkProjection(const cv::Mat& p, const std::string& where, const std::string& entry) {
    checkMatrix(p, where, entry, 3, 4);
    if (p.at<double>(0, 0) <= 0 || p.at<double>(1, 1) <= 0) {
        failEntry(where, entry, "focal lengths must be positive");
    }
    if (p.at<double>(2, 0) != 0 || p.at<double>(2, 1) != 0 || p.at<double>(2, 2) != 1 || p.at<double>(2, 3) != 0) {
        failEntry(where, entry, "is not a projection matrix (last row must be 0 0 1 0)");
    }
}

void checkDistortion(const cv::Mat& d, const std::string& where, const std::string& entry) {
    if (d.empty()) {
        failEntry(where, entry, "missing");
    }
    const int n = static_cast<int>(d.total());
    if ((d.rows != 1 && d.cols != 1) || (n != 4 && n != 5 && n != 8 && n != 12 && n != 14)) {
        failEntry(where, entry, "must be a vector of 4, 5, 8, 12 or 14 coefficients");
    }
    if (d.type() != CV_64FC1 || !cv::checkRange(d)) {
        failEntry(where, entry, "must hold finite double-precision numbers");
    }
}

// The whole file is parsed by yaml-cpp and the matrices built from its nodes: OpenCV's FileStorage
// parser loops for ever on some malformed files (a 101-byte fuzzed one, OpenCV 4.6) and asserts
// on others, so it never sees a file to be read. Every problem is an Error(65) naming the entry.
constexpr std::size_t kMaxCalibrationBytes = 1 << 20;

std::string markText(const YAML::Mark& mark) {
    return mark.is_null() ? std::string() : " (line " + std::to_string(mark.line + 1) + ", column " +
                                                std::to_string(mark.column + 1) + ")";
}

// what names the part of the entry in the message ("rows ", "data[3] "), empty for the entry itself.
int intOf(const YAML::Node& node, const std::string& where, const std::string& entry, const std::string& what = "") {
    try {
        if (node.IsScalar()) return node.as<int>();
    } catch (const YAML::Exception&) {
    }
    failEntry(where, entry, what + "must be an integer" + markText(node.Mark()));
}

double numberOf(const YAML::Node& node, const std::string& where, const std::string& entry, const std::string& what) {
    try {
        if (node.IsScalar()) return node.as<double>();
    } catch (const YAML::Exception&) {
    }
    failEntry(where, entry, what + "is not a number" + markText(node.Mark()));
}

// An !!opencv-matrix: rows, cols, dt (one channel) and rows*cols numbers in data.
cv::Mat readMat(const YAML::Node& top, const std::string& where, const std::string& name) {
    const YAML::Node node = top[name];
    if (!node) {
        return {};
    }
    if (!node.IsMap()) {
        failEntry(where, name, "must be an OpenCV matrix (!!opencv-matrix with rows, cols, dt and data)");
    }
    const int rows = intOf(node["rows"], where, name, "rows "), cols = intOf(node["cols"], where, name, "cols ");
    if (rows < 1 || cols < 1 || rows > kMaxMatrixSide || cols > kMaxMatrixSide) {
        failEntry(where, name, "rows and cols must be between 1 and " + std::to_string(kMaxMatrixSide));
    }
    const YAML::Node dt = node["dt"];
    static const std::string kSingleChannel = "ucwsifd";
    if (!dt || !dt.IsScalar() || dt.Scalar().size() != 1 || kSingleChannel.find(dt.Scalar()) == std::string::npos) {
        failEntry(where, name, "dt must name a single-channel element type (d for double)");
    }
    const YAML::Node data = node["data"];
    if (!data || !data.IsSequence()) {
        failEntry(where, name, "data must be a list of numbers");
    }
    const std::size_t expected = static_cast<std::size_t>(rows) * static_cast<std::size_t>(cols);
    if (data.size() != expected) {
        failEntry(where, name, "data holds " + std::to_string(data.size()) + " numbers, " + std::to_string(rows) +
                                   "x" + std::to_string(cols) + " needs " + std::to_string(expected));
    }
    cv::Mat m(rows, cols, CV_64F);
    for (std::size_t i = 0; i < expected; ++i) {
        m.ptr<double>()[i] = numberOf(data[i], where, name, "data[" + std::to_string(i) + "] ");  // continuous
    }
    return m;
}

int readInt(const YAML::Node& top, const std::string& where, const std::string& name) {
    const YAML::Node node = top[name];
    if (!node) {
        failEntry(where, name, "missing");
    }
    return intOf(node, where, name);
}

// The file's text as yaml-cpp takes it: OpenCV writes the directive as "%YAML:1.0", which is not
// YAML's "%YAML 1.0".
std::string readCalibrationText(const std::filesystem::path& path, const std::string& where) {
    std::ifstream in(path, std::ios::binary);
    std::string text(kMaxCalibrationBytes + 1, '\0');
    in.read(text.data(), static_cast<std::streamsize>(text.size()));
    if (in.bad()) {
        throw Error(kExitNoInput, where + ": cannot read the calibration file");
    }
    text.resize(static_cast<std::size_t>(in.gcount()));
    if (text.size() > kMaxCalibrationBytes) {
        throw Error(kExitDataErr, where + ": larger than " + std::to_string(kMaxCalibrationBytes) +
                                      " bytes: not a calibration file");
    }
    if (text.rfind("%YAML:", 0) == 0) {
        text.erase(0, text.find('\n') == std::string::npos ? text.size() : text.find('\n'));
    }
    return text;
}

}  // namespace

StereoCalibration parseCalibration(const std::string& text, const std::string& where) {
    YAML::Node top;
    try {
        top = YAML::Load(text);
    } catch (const YAML::Exception& e) {
        throw Error(kExitDataErr, where + ": not a YAML calibration file: " + e.msg + markText(e.mark));
    }
    if (!top.IsMap()) {
        throw Error(kExitDataErr, where + ": top level: must be a map of named entries (M1, D1, ...), got " +
                                      (top.IsSequence() ? "a sequence" : top.IsScalar() ? "a scalar" : "nothing"));
    }
    StereoCalibration c;
    try {
        c.M1 = readMat(top, where, "M1");
        c.D1 = readMat(top, where, "D1");
        c.M2 = readMat(top, where, "M2");
        c.D2 = readMat(top, where, "D2");
        c.R = readMat(top, where, "R");
        c.T = readMat(top, where, "T");
        c.imageSize.width = readInt(top, where, "image_width");
        c.imageSize.height = readInt(top, where, "image_height");
        c.R1 = readMat(top, where, "R1");
        c.R2 = readMat(top, where, "R2");
        c.P1 = readMat(top, where, "P1");
        c.P2 = readMat(top, where, "P2");
        c.Q = readMat(top, where, "Q");
    } catch (const YAML::Exception& e) {
        // A key lookup on a node of odd shape (an alias cycle, a complex key): still the file's fault.
        throw Error(kExitDataErr, where + ": not a calibration file: " + e.msg + markText(e.mark));
    }
    if (!c.T.empty() && c.T.rows == 1 && c.T.cols == 3) {
        c.T = c.T.t();
    }
    validateCalibration(c, where);
    if (c.R1.empty() || c.R2.empty() || c.P1.empty() || c.P2.empty() || c.Q.empty()) {
        deriveRectification(c);
    }
    return c;
}

double StereoCalibration::baselineMm() const {
    return T.empty() ? 0.0 : cv::norm(T);
}

double StereoCalibration::rectifiedFocalPx() const {
    return P1.empty() ? 0.0 : P1.at<double>(0, 0);
}

void deriveRectification(StereoCalibration& c) {
    cv::stereoRectify(c.M1, c.D1, c.M2, c.D2, c.imageSize, c.R, c.T, c.R1, c.R2, c.P1, c.P2, c.Q,
                      cv::CALIB_ZERO_DISPARITY, 0.0, c.imageSize);
}

StereoCalibration nominalCalibration(cv::Size eyeSize, double horizontalFovDeg, double baselineMm) {
    if (eyeSize.width <= 0 || eyeSize.height <= 0 || horizontalFovDeg <= 0 || horizontalFovDeg >= 180 ||
        baselineMm <= 0) {
        throw InvalidInput("nominal calibration needs a positive eye size, a field of view in (0, 180) "
                           "degrees and a positive baseline");
    }
    const double f = 0.5 * eyeSize.width / std::tan(0.5 * horizontalFovDeg * kPi / 180.0);
    StereoCalibration c;
    c.imageSize = eyeSize;
    c.M1 = (cv::Mat_<double>(3, 3) << f, 0, (eyeSize.width - 1) / 2.0, 0, f, (eyeSize.height - 1) / 2.0, 0, 0, 1);
    c.M2 = c.M1.clone();
    c.D1 = cv::Mat::zeros(1, 5, CV_64F);
    c.D2 = cv::Mat::zeros(1, 5, CV_64F);
    c.R = cv::Mat::eye(3, 3, CV_64F);
    // OpenCV's T maps left-camera points into the right camera: a right eye B to the right of the
    // left one sees the world shifted by -B.
    c.T = (cv::Mat_<double>(3, 1) << -baselineMm, 0, 0);
    deriveRectification(c);
    return c;
}

void validateCalibration(const StereoCalibration& c, const std::string& where) {
    if (c.imageSize.width <= 0 || c.imageSize.height <= 0 || c.imageSize.width > kMaxEyeSidePx ||
        c.imageSize.height > kMaxEyeSidePx) {
        failEntry(where, "image_width/image_height", "must be between 1 and " + std::to_string(kMaxEyeSidePx));
    }
    checkCameraMatrix(c.M1, where, "M1", c.imageSize);
    checkCameraMatrix(c.M2, where, "M2", c.imageSize);
    checkDistortion(c.D1, where, "D1");
    checkDistortion(c.D2, where, "D2");
    checkRotation(c.R, where, "R");
    checkMatrix(c.T, where, "T", 3, 1);
    if (c.baselineMm() < 1e-6) {
        failEntry(where, "T", "baseline is zero");
    }
    if (!c.R1.empty()) checkRotation(c.R1, where, "R1");
    if (!c.R2.empty()) checkRotation(c.R2, where, "R2");
    if (!c.P1.empty()) checkProjection(c.P1, where, "P1");
    if (!c.P2.empty()) checkProjection(c.P2, where, "P2");
    if (!c.Q.empty()) {
        checkMatrix(c.Q, where, "Q", 4, 4);
        // Q(3,2) is -1/Tx: zero would put every point at infinite depth.
        if (c.Q.at<double>(3, 2) == 0) {
            failEntry(where, "Q", "has no baseline term (Q[3][2] is zero)");
        }
    }
}

StereoCalibration loadCalibration(const std::filesystem::path& path) {
    const std::string where = path.string();
    if (!std::filesystem::is_regular_file(path)) {
        throw Error(kExitNoInput, where + ": calibration file not found");
    }
    return parseCalibration(readCalibrationText(path, where), where);
}

void saveCalibration(const std::filesystem::path& path, const StereoCalibration& calibration) {
    saveCalibration(path, calibration, "");
}

void saveCalibration(const std::filesystem::path& path, const StereoCalibration& calibration,
                     const std::string& comment) {
    StereoCalibration c = calibration;
    validateCalibration(c, path.string());
    if (c.R1.empty() || c.P1.empty() || c.Q.empty()) {
        deriveRectification(c);
    }
    // Written beside the target and renamed over it, so a reader (the daemon at start-up) sees the
    // old file or the new one, never half of one. The partial file keeps the extension because
    // FileStorage picks YAML, XML or JSON from it.
    const std::filesystem::path partial =
        path.parent_path() / ("." + path.stem().string() + "-partial" + path.extension().string());
    const std::string where = path.string();
    if (!std::ofstream(partial)) {
        // Checked before FileStorage tries, which would also print its own error line.
        throw Error(kExitCantCreate, where + ": cannot write calibration (cannot create " + partial.string() + ")");
    }
    try {
        cv::FileStorage fs;
        if (!fs.open(partial.string(), cv::FileStorage::WRITE)) {
            throw Error(kExitCantCreate, where + ": cannot write calibration");
        }
        std::string::size_type start = 0;
        while (start < comment.size()) {
            const auto end = std::min(comment.find('\n', start), comment.size());
            fs.writeComment(comment.substr(start, end - start));
            start = end + 1;
        }
        fs << "image_width" << c.imageSize.width << "image_height" << c.imageSize.height;
        fs << "M1" << c.M1 << "D1" << c.D1 << "M2" << c.M2 << "D2" << c.D2;
        fs << "R" << c.R << "T" << c.T;
        fs << "R1" << c.R1 << "R2" << c.R2 << "P1" << c.P1 << "P2" << c.P2 << "Q" << c.Q;
        fs.release();
    } catch (const cv::Exception& e) {
        std::error_code ignored;
        std::filesystem::remove(partial, ignored);
        throw Error(kExitCantCreate, where + ": cannot write calibration (" + e.err + ")");
    }
    std::error_code error;
    std::filesystem::rename(partial, path, error);
    if (error) {
        std::error_code ignored;
        std::filesystem::remove(partial, ignored);
        throw Error(kExitCantCreate, where + ": cannot write calibration (" + error.message() + ")");
    }
}

void checkFrameSize(const StereoCalibration& calibration, cv::Size frameSize, const std::string& calibrationName) {
    const cv::Size eye = calibration.imageSize;
    const cv::Size expected(2 * eye.width, eye.height);
    if (frameSize != expected) {
        throw InvalidInput("frame is " + sizeText(frameSize) + ", but " + calibrationName + " is for eyes of " +
                           sizeText(eye) + " (a " + sizeText(expected) + " side-by-side frame)");
    }
}

Rectifier::Rectifier(const StereoCalibration& c) : calibration_(c), imageSize_(c.imageSize) {
    if (calibration_.R1.empty() || calibration_.P1.empty()) {
        deriveRectification(calibration_);
    }
    buildMaps();
}

void Rectifier::buildMaps() {
    // Fixed-point maps (CV_16SC2 + interpolation table): half the memory and faster remaps.
    const StereoCalibration& c = calibration_;
    leftMap1_ = leftMap2_ = rightMap1_ = rightMap2_ = cv::Mat();  // the old ones go first
    cv::initUndistortRectifyMap(c.M1, c.D1, c.R1, c.P1, imageSize_, CV_16SC2, leftMap1_, leftMap2_);
    cv::initUndistortRectifyMap(c.M2, c.D2, c.R2, c.P2, imageSize_, CV_16SC2, rightMap1_, rightMap2_);
    mapped_ = cv::Rect({0, 0}, imageSize_);
}

void Rectifier::focus(const cv::Rect& box) {
    if ((box & cv::Rect({0, 0}, imageSize_)) != box || box.empty()) {
        throw InvalidInput("rectification box lies outside the " + sizeText(imageSize_) + " image");
    }
    if (box == mapped_) return;
    if ((box & mapped_) != box) buildMaps();
    const cv::Rect inMaps = box - mapped_.tl();
    for (cv::Mat* m : {&leftMap1_, &leftMap2_, &rightMap1_, &rightMap2_}) *m = (*m)(inMaps).clone();
    mapped_ = box;
}

StereoPair Rectifier::rectify(const StereoPair& pair) const { return rectify(pair, cv::Rect({0, 0}, imageSize_)); }

void Rectifier::checkInputs(cv::Size left, cv::Size right, const cv::Rect& box) const {
    if (left != imageSize_ || right != imageSize_) {
        throw InvalidInput("frame eye size " + sizeText(left) + " does not match the calibration's " +
                           sizeText(imageSize_));
    }
    if ((box & cv::Rect({0, 0}, imageSize_)) != box || box.empty()) {
        throw InvalidInput("rectification box lies outside the " + sizeText(imageSize_) + " image");
    }
    if ((box & mapped_) != box) {
        throw InvalidInput("rectification box lies outside the part of the maps kept (Rectifier::focus)");
    }
}

StereoPair Rectifier::rectify(const StereoPair& pair, const cv::Rect& box) const {
    checkInputs(pair.left.size(), pair.right.size(), box);
    // The maps are per output pixel: a box of them rectifies that part alone.
    const cv::Rect inMaps = box - mapped_.tl();
    StereoPair out;
    cv::remap(pair.left, out.left, leftMap1_(inMaps), leftMap2_(inMaps), cv::INTER_LINEAR, cv::BORDER_CONSTANT);
    cv::remap(pair.right, out.right, rightMap1_(inMaps), rightMap2_(inMaps), cv::INTER_LINEAR, cv::BORDER_CONSTANT);
    return out;
}

cv::Mat Rectifier::rectifyLeft(const cv::Mat& left, const cv::Rect& box) const {
    checkInputs(left.size(), left.size(), box);
    const cv::Rect inMaps = box - mapped_.tl();
    cv::Mat out;
    cv::remap(left, out, leftMap1_(inMaps), leftMap2_(inMaps), cv::INTER_LINEAR, cv::BORDER_CONSTANT);
    return out;
}

}  // namespace icewatch::calib
