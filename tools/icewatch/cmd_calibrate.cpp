// icewatch calibrate: the commissioning step. Calibrates the stereo pair from chessboard views
// (a recording of the side-by-side camera or an OpenCV image list) and writes calibration.yaml;
// with --nominal, writes the ideal HBVCAM model for a camera mode instead (the files in
// config/calibration/ are made this way).
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>

#include <nlohmann/json.hpp>

#include "core/calib/chessboard_calibration.hpp"
#include "core/calib/stereo_calibration.hpp"
#include "core/common/error.hpp"
#include "drivers/log/log.hpp"
#include "tools/icewatch/calibration_pairs.hpp"
#include "tools/icewatch/command.hpp"
#include "tools/icewatch/terminal.hpp"

namespace icewatch::cli {

namespace {

struct CalibrateOptions {
    std::string pairs;
    std::string board = "9x6";
    double squareMm = 0;
    int step = 1;
    bool nominal = false;
    std::string mode;
    double hfovDeg = 80.0;
    double baselineMm = 60.0;
    std::string out;
    bool json = false;
};

// "9x6", "2560x720": two positive integers separated by 'x'.
cv::Size parseSize(const std::string& text, const std::string& option) {
    int width = 0, height = 0;
    char x = 0, extra = 0;
    if (std::sscanf(text.c_str(), "%d%c%d%c", &width, &x, &height, &extra) != 3 || x != 'x' || width <= 0 ||
        height <= 0) {
        throw Error(kExitUsage, option + ": expected WIDTHxHEIGHT (e.g. 9x6), got \"" + text + "\"");
    }
    return {width, height};
}

std::string sizeText(cv::Size s) { return std::to_string(s.width) + "x" + std::to_string(s.height); }

int runNominal(const CalibrateOptions& o) {
    if (!o.pairs.empty()) {
        throw Error(kExitUsage, "--nominal and --pairs exclude each other");
    }
    if (o.mode.empty()) {
        throw Error(kExitUsage, "--nominal needs --mode, the side-by-side frame size (e.g. 2560x720)");
    }
    const cv::Size frame = parseSize(o.mode, "--mode");
    if (frame.width % 2 != 0) {
        throw Error(kExitUsage, "--mode: the width must be even: the frame holds two equal eyes side by side");
    }
    const cv::Size eye(frame.width / 2, frame.height);
    const calib::StereoCalibration c = calib::nominalCalibration(eye, o.hfovDeg, o.baselineMm);
    std::ostringstream comment;
    comment << "Nominal HBVCAM calibration (pinhole, no distortion, principal point at the centre) for the "
            << o.mode << " side-by-side mode, " << sizeText(eye) << " per eye, " << o.hfovDeg << " deg HFOV, "
            << o.baselineMm << " mm baseline. Made by:\n"
            << "icewatch calibrate --nominal --mode " << o.mode << " --hfov-deg " << o.hfovDeg << " --baseline-mm "
            << o.baselineMm << " --out THIS_FILE\n"
            << "A real box is calibrated with a chessboard at commissioning (README, Calibration).";
    calib::saveCalibration(o.out, c, comment.str());
    if (o.json) {
        std::cout << nlohmann::json{{"calibration", o.out},
                                    {"nominal", true},
                                    {"image_width", eye.width},
                                    {"image_height", eye.height},
                                    {"focal_px", c.M1.at<double>(0, 0)},
                                    {"baseline_mm", c.baselineMm()}}
                         .dump()
                  << "\n";
    } else {
        std::cout << "wrote nominal calibration " << o.out << " (" << sizeText(eye) << " per eye, f "
                  << c.M1.at<double>(0, 0) << " px, baseline " << c.baselineMm() << " mm)\n";
    }
    return kExitOk;
}

int runChessboard(const CalibrateOptions& o) {
    if (o.pairs.empty()) {
        throw Error(kExitUsage, "calibrate needs --pairs DIR_OR_LIST (or --nominal --mode WxH)");
    }
    if (!(o.squareMm > 0)) {
        throw Error(kExitUsage, "--square-mm: the side of one chessboard square in millimetres must be positive");
    }
    // Found out before minutes of corner search, not after.
    const std::filesystem::path outDir = std::filesystem::path(o.out).parent_path();
    if (!outDir.empty() && !std::filesystem::is_directory(outDir)) {
        throw Error(kExitCantCreate, o.out + ": cannot write calibration (no directory " + outDir.string() + ")");
    }
    const auto logger = log::get("calib");
    calib::ChessboardCalibrator calibrator({parseSize(o.board, "--board"), o.squareMm});
    int seen = 0;
    Progress progress("calibrate");
    forEachCalibrationPair(o.pairs, o.step, [&](const std::string& name, const StereoPair& pair) {
        ++seen;
        progress.show("corners in pair " + std::to_string(seen) + " (" + name + ")");
        if (calibrator.addView(name, pair)) {
            logger->debug("{}: chessboard found in both eyes", name);
        } else {
            progress.done();  // the warning on a line of its own
            logger->warn("{}: skipped: {}", name, calibrator.skipped().back().reason);
        }
    });
    progress.show("calibrating from " + std::to_string(calibrator.viewsUsed()) + " pairs");
    const calib::ChessboardCalibrationResult r = calibrator.calibrate();
    progress.done();
    const calib::StereoCalibration& c = r.calibration;

    std::ostringstream comment;
    comment << "Chessboard calibration from " << o.pairs << ": board " << o.board << ", square " << o.squareMm
            << " mm, " << r.used.size() << " pairs used, " << r.skipped.size() << " skipped.\n"
            << "rms_px " << r.rmsPx << ", epipolar_px " << r.epipolarPx << " (mean |y_left - y_right| after "
            << "rectification), baseline " << c.baselineMm() << " mm.";
    calib::saveCalibration(o.out, c, comment.str());

    if (o.json) {
        nlohmann::json skipped = nlohmann::json::array(), views = nlohmann::json::array();
        for (const calib::SkippedView& s : r.skipped) {
            skipped.push_back({{"name", s.name}, {"reason", s.reason}});
        }
        for (const calib::ViewError& v : r.used) {
            views.push_back({{"name", v.name}, {"left_rms_px", v.leftRmsPx}, {"right_rms_px", v.rightRmsPx}});
        }
        std::cout << nlohmann::json{{"calibration", o.out},
                                    {"rms_px", r.rmsPx},
                                    {"epipolar_px", r.epipolarPx},
                                    {"max_epipolar_px", r.maxEpipolarPx},
                                    {"pairs_used", r.used.size()},
                                    {"pairs_skipped", r.skipped.size()},
                                    {"skipped", skipped},
                                    {"views", views},
                                    {"image_width", c.imageSize.width},
                                    {"image_height", c.imageSize.height},
                                    {"focal_px", {c.M1.at<double>(0, 0), c.M2.at<double>(0, 0)}},
                                    {"rectified_focal_px", c.rectifiedFocalPx()},
                                    {"baseline_mm", c.baselineMm()}}
                         .dump()
                  << "\n";
    } else {
        std::cout << "wrote " << o.out << ": " << r.used.size() << " of " << seen << " pairs used, rms_px "
                  << r.rmsPx << ", epipolar_px " << r.epipolarPx << ", baseline " << c.baselineMm() << " mm\n";
        for (const calib::SkippedView& s : r.skipped) {
            std::cout << "skipped " << s.name << ": " << s.reason << "\n";
        }
    }
    return kExitOk;
}

}  // namespace

void addCalibrateCommand(CLI::App& app, const GlobalOptions& /*global*/, RunFunction& run) {
    CLI::App* cmd = app.add_subcommand("calibrate", "stereo calibration from chessboard pairs (or the nominal model)");
    auto o = std::make_shared<CalibrateOptions>();
    cmd->add_option("--pairs", o->pairs,
                    "directory of side-by-side frames (an `icewatch record` recording) or an OpenCV image-list XML "
                    "(left/right alternating)");
    cmd->add_option("--board", o->board, "inner corners of the chessboard, columns x rows")->capture_default_str();
    cmd->add_option("--square-mm", o->squareMm, "side of one chessboard square in millimetres (sets the unit of T)");
    cmd->add_option("--step", o->step, "use every N-th pair (recordings hold many near-identical frames)")
        ->capture_default_str();
    cmd->add_flag("--nominal", o->nominal, "write the ideal HBVCAM model instead of calibrating");
    cmd->add_option("--mode", o->mode, "with --nominal: side-by-side frame size, e.g. 2560x720");
    cmd->add_option("--hfov-deg", o->hfovDeg, "with --nominal: horizontal field of view")->capture_default_str();
    cmd->add_option("--baseline-mm", o->baselineMm, "with --nominal: baseline")->capture_default_str();
    cmd->add_option("--out", o->out, "calibration file to write (OpenCV FileStorage YAML)")->required();
    cmd->add_flag("--json", o->json, "print the result as one JSON object");
    cmd->callback([&run, o] { run = [o] { return o->nominal ? runNominal(*o) : runChessboard(*o); }; });
}

}  // namespace icewatch::cli
