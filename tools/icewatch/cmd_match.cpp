// icewatch match: one rectified pair -> a left-view disparity (PFM), optionally a picture, and a
// one-line summary (or --json).
#include <algorithm>
#include <iomanip>
#include <iostream>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "core/pictures/debug_directory.hpp"
#include "core/pictures/measurement_pictures.hpp"
#include "core/stereo/disparity_io.hpp"
#include "tools/icewatch/command.hpp"
#include "tools/icewatch/stereo_options.hpp"

namespace icewatch::cli {

void addMatchCommand(CLI::App& app, const GlobalOptions& /*global*/, RunFunction& run) {
    CLI::App* command = app.add_subcommand("match", "compute the disparity of a rectified stereo pair");
    struct Options {
        StereoOptions stereo;
        std::string out, colour;
        bool json = false;
    };
    auto o = std::make_shared<Options>();
    addStereoOptions(*command, o->stereo);
    command->add_option("--out", o->out, "disparity output (PFM, float, left view; invalid = inf)")->required();
    command->add_option("--color", o->colour,
                        "false-colour picture of the disparity on the band searched, with its colour bar (PNG)");
    command->add_flag("--json", o->json, "print the result as one JSON object");
    command->callback([&run, o] {
        run = [o] {
            const cv::Mat left = readImage(o->stereo.left, cv::IMREAD_COLOR);
            const cv::Mat right = readImage(o->stereo.right, cv::IMREAD_COLOR);
            stereo::Matcher matcher(stereo::parseMethod(o->stereo.method), stereoParameters(o->stereo));
            const double start = nowMs();
            const cv::Mat disparity = matcher.compute(left, right, o->stereo.range());
            const double elapsedMs = nowMs() - start;
            stereo::writePfm(o->out, disparity);
            if (!o->colour.empty()) {
                pictures::writePicture(o->colour, pictures::disparityPicture(disparity, o->stereo.minDisparity,
                                                                             o->stereo.maxDisparity));
            }
            const double validPercent = 100.0 * cv::countNonZero(disparity >= 0) / std::max(1, int(disparity.total()));
            if (o->json) {
                std::cout << nlohmann::json{{"out", o->out},
                                            {"color", o->colour.empty() ? nlohmann::json(nullptr) : nlohmann::json(o->colour)},
                                            {"method", o->stereo.method},
                                            {"width", disparity.cols},
                                            {"height", disparity.rows},
                                            {"min_disp", o->stereo.minDisparity},
                                            {"max_disp", o->stereo.maxDisparity},
                                            {"valid_percent", validPercent},
                                            {"match_ms", elapsedMs}}
                                 .dump()
                          << "\n";
            } else {
                std::cout << "disparity " << disparity.cols << "x" << disparity.rows << " on [" << o->stereo.minDisparity
                          << ", " << o->stereo.maxDisparity << ") px, " << std::fixed << std::setprecision(1)
                          << validPercent << " % valid, " << std::setprecision(0) << elapsedMs << " ms (" << o->stereo.method
                          << "), written to " << o->out << "\n";
            }
            return 0;
        };
    });
}

}  // namespace icewatch::cli
