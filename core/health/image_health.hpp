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
    // Both as if a scene dimmer than kReferenceLevel were lit to it: light scales every grey
    // difference alike, so a darker day does not read as blur or fog (which change the image's
    // structure, not its exposure). Brighter scenes are taken as they are (the limits were set on
    // well-lit ones).
    double sharpness = 0.0;         // variance of the 3x3 Laplacian of the grey image at 1/4 scale
    double contrast = 0.0;          // standard deviation of the grey level, in the most varied tile
                                    // of a 4 x 4 grid
    std::vector<HealthProblem> problems;

    bool ok() const { return problems.empty(); }
};

inline constexpr double kReferenceLevel = 128.0;

// The factor that brings the grey differences of an image of this mean level to the reference
// exposure: 1 at or above it, and for a black image (nothing to scale).
inline double exposureScale(double meanLevel) {
    return meanLevel > 1.0 && meanLevel < kReferenceLevel ? kReferenceLevel / meanLevel : 1.0;
}

// Judges one 8-bit image (grey or BGR). Throws InvalidInput on an empty or non-8-bit image.
ImageHealth checkImageHealth(const cv::Mat& image, const config::ImageHealthConfig& limits);

}  // namespace icewatch::health
