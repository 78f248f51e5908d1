#pragma once

#include <string>

#include <CLI/CLI.hpp>
#include <opencv2/core.hpp>

#include "core/stereo/matcher.hpp"

namespace icewatch::cli {

// What match, eval and bench share: the pair, the range, the method and where parameters come from.
struct StereoOptions {
    std::string left;
    std::string right;
    int minDisparity = 0;
    int maxDisparity = 0;
    std::string method = "paper";
    std::string config;  // optional icewatch.json whose "stereo" section sets the parameters

    stereo::DisparityRange range() const { return {minDisparity, maxDisparity}; }
};

// Registers --left, --right, --min-disp, --max-disp, --config (and --method unless withMethod is false).
void addStereoOptions(CLI::App& command, StereoOptions& options, bool withMethod = true);

// Reads an image; a missing or unreadable file throws Error(kExitNoInput) naming it.
cv::Mat readImage(const std::string& path, int flags);

// Parameters from the --config file's "stereo" section, or the built-in defaults.
stereo::Parameters stereoParameters(const StereoOptions& options);

// Milliseconds since some fixed point, for timing matching.
double nowMs();

}  // namespace icewatch::cli
