#pragma once

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/config/config.hpp"

namespace icewatch::health {

// One failed check: a short flag (dark, saturated, blurred, low_contrast) and why, with figures.
struct HealthProblem {
    std::string flag;
    std::string reason;
};

// Figures of one image (an eye) and the checks it failed.
struct ImageHealth {
    double meanLevel = 0.0;         // mean grey level, 0-255
    double saturatedPercent = 0.0;  // pixels at 250 or more
    double sharpness = 0.0;         // variance of the 3x3 Laplacian of the grey image at 1/4 scale
    double contrast = 0.0;          // standard deviation of the grey level
    std::vector<HealthProblem> problems;

    bool ok() const { return problems.empty(); }
};

// Judges one 8-bit image (grey or BGR). Throws InvalidInput on an empty or non-8-bit image.
ImageHealth checkImageHealth(const cv::Mat& image, const config::ImageHealthConfig& limits);

}  // namespace icewatch::health
