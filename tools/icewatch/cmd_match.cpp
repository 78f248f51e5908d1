// icewatch match: one rectified pair -> a left-view disparity (PFM) and optionally a picture.
#include <iostream>

#include <opencv2/imgcodecs.hpp>

#include "core/common/error.hpp"
#include "core/stereo/disparity_io.hpp"
#include "tools/icewatch/command.hpp"
#include "tools/icewatch/stereo_options.hpp"

namespace icewatch::cli {

void addMatchCommand(CLI::App& app, const GlobalOptions& /*global*/, RunFunction& run) {
    CLI::App* command = app.add_subcommand("match", "compute the disparity of a rectified stereo pair");
    auto options = std::make_shared<StereoOptions>();
    auto out = std::make_shared<std::string>();
    auto colour = std::make_shared<std::string>();
    addStereoOptions(*command, *options);
    command->add_option("--out", *out, "disparity output (PFM, float, left view; invalid = inf)")->required();
    command->add_option("--color", *colour, "false-colour picture of the disparity (PNG)");
    command->callback([&run, options, out, colour] {
        run = [options, out, colour] {
            const cv::Mat left = readImage(options->left, cv::IMREAD_COLOR);
            const cv::Mat right = readImage(options->right, cv::IMREAD_COLOR);
            stereo::Matcher matcher(stereo::parseMethod(options->method), stereoParameters(*options));
            const cv::Mat disparity = matcher.compute(left, right, options->range());
            stereo::writePfm(*out, disparity);
            if (!colour->empty()) {
                bool written = false;
                try {
                    written = cv::imwrite(*colour, stereo::colorizeDisparity(disparity, options->maxDisparity));
                } catch (const cv::Exception&) {
                    written = false;
                }
                if (!written) throw Error(kExitCantCreate, *colour + ": cannot write the picture");
            }
            return 0;
        };
    });
}

}  // namespace icewatch::cli
