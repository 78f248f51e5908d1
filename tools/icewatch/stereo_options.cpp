// Options and helpers shared by the stereo subcommands (match, eval, bench).
#include "tools/icewatch/stereo_options.hpp"

#include <chrono>

#include <opencv2/imgcodecs.hpp>

#include "core/common/error.hpp"
#include "core/config/config.hpp"

namespace icewatch::cli {

void addStereoOptions(CLI::App& command, StereoOptions& options, bool withMethod) {
    command.add_option("--left", options.left, "left image (rectified)")->required();
    command.add_option("--right", options.right, "right image (rectified)")->required();
    command.add_option("--min-disp", options.minDisparity, "smallest disparity searched (default 0)");
    command.add_option("--max-disp", options.maxDisparity, "disparities searched: min-disp .. max-disp - 1")->required();
    if (withMethod) {
        command.add_option("--method", options.method, "paper, adcensus or sgbm")
            ->check(CLI::IsMember({"paper", "adcensus", "sgbm"}));
    }
    command.add_option("--config", options.config, "configuration file whose \"stereo\" section sets the parameters");
}

cv::Mat readImage(const std::string& path, int flags) {
    cv::Mat image;
    try {
        image = cv::imread(path, flags);
    } catch (const cv::Exception&) {
        image.release();
    }
    if (image.empty()) throw Error(kExitNoInput, path + ": cannot read the image (missing, unreadable or not an image)");
    return image;
}

stereo::Parameters stereoParameters(const StereoOptions& options) {
    if (options.config.empty()) return {};
    return config::loadConfig(options.config).stereo;
}

double nowMs() {
    using Clock = std::chrono::steady_clock;
    return std::chrono::duration<double, std::milli>(Clock::now().time_since_epoch()).count();
}

}  // namespace icewatch::cli
