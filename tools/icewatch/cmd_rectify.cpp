// icewatch rectify: applies a calibration to one side-by-side frame and writes what a person needs
// to judge it by eye: both rectified eyes, and the two side by side with horizontal lines every
// 32 px, along which the same feature must sit at the same height in both eyes.
#include <iostream>
#include <memory>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/calib/stereo_calibration.hpp"
#include "core/common/error.hpp"
#include "tools/icewatch/calibration_pairs.hpp"
#include "tools/icewatch/command.hpp"
#include "tools/icewatch/terminal.hpp"

namespace icewatch::cli {

namespace {

namespace fs = std::filesystem;

constexpr int kLineSpacingPx = 32;

struct RectifyOptions {
    std::string calibration;
    std::string frame;
    std::string out;
    bool json = false;
    bool force = false;
};

void writeImage(const fs::path& path, const cv::Mat& image) {
    bool written = false;
    try {
        written = cv::imwrite(path.string(), image);
    } catch (const cv::Exception& e) {
        throw Error(kExitCantCreate, path.string() + ": cannot write image (" + e.err + ")");
    }
    if (!written) {
        throw Error(kExitCantCreate, path.string() + ": cannot write image");
    }
}

// Alternating colours so a line is visible on bright and dark content alike.
cv::Mat withEpipolarLines(const cv::Mat& sideBySide) {
    cv::Mat picture = sideBySide.clone();
    for (int y = kLineSpacingPx; y < picture.rows; y += kLineSpacingPx) {
        const cv::Scalar colour = (y / kLineSpacingPx) % 2 == 0 ? cv::Scalar(0, 255, 0) : cv::Scalar(255, 0, 255);
        cv::line(picture, {0, y}, {picture.cols - 1, y}, colour, 1, cv::LINE_8);
    }
    return picture;
}

int runRectify(const RectifyOptions& o) {
    const calib::StereoCalibration calibration = calib::loadCalibration(o.calibration);
    const cv::Mat frame = readImage(o.frame);
    try {
        calib::checkFrameSize(calibration, frame.size(), o.calibration);
    } catch (const Error& e) {
        throw Error(e.code(), o.frame + ": " + e.what());
    }
    const cv::Size eye = calibration.imageSize;
    const calib::Rectifier rectifier(calibration);
    const StereoPair rectified = rectifier.rectify(splitSideBySide(frame));

    const fs::path dir(o.out);
    checkOutputDirectory(dir, o.force, "--out");
    std::error_code error;
    fs::create_directories(dir, error);
    if (error || !fs::is_directory(dir)) {
        throw Error(kExitCantCreate, o.out + ": cannot create output directory" + (error ? " (" + error.message() + ")" : ""));
    }
    const fs::path left = dir / "left.png", right = dir / "right.png", lines = dir / "rectified_lines.png";
    writeImage(left, rectified.left);
    writeImage(right, rectified.right);
    writeImage(lines, withEpipolarLines(joinSideBySide(rectified.left, rectified.right)));
    if (o.json) {
        std::cout << nlohmann::json{{"left", left.string()},
                                    {"right", right.string()},
                                    {"side_by_side", lines.string()},
                                    {"image_width", eye.width},
                                    {"image_height", eye.height}}
                         .dump()
                  << "\n";
    } else {
        std::cout << "wrote " << left.string() << ", " << right.string() << " and " << lines.string() << "\n";
    }
    return kExitOk;
}

}  // namespace

void addRectifyCommand(CLI::App& app, const GlobalOptions& /*global*/, RunFunction& run) {
    CLI::App* cmd = app.add_subcommand("rectify", "rectify one side-by-side frame with a calibration, for checking by eye");
    auto o = std::make_shared<RectifyOptions>();
    cmd->add_option("--calib", o->calibration, "calibration file (icewatch calibrate)")->required();
    cmd->add_option("--frame", o->frame, "side-by-side frame (.jpg, .png), left eye = left half")->required();
    cmd->add_option("--out", o->out, "output directory: left.png, right.png, rectified_lines.png")->required();
    cmd->add_flag("--json", o->json, "print the written files as one JSON object");
    addForceFlag(*cmd, o->force);
    cmd->callback([&run, o] { run = [o] { return runRectify(*o); }; });
}

}  // namespace icewatch::cli
