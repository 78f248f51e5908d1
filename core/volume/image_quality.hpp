#pragma once

#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "core/volume/parameters.hpp"

namespace icewatch::volume {

// What the quality gate looks at in an image, inside the region.
struct ImageQuality {
    double meanGrey = 0;          // 0..255
    double saturatedPercent = 0;  // pixels at >= 250
    // Mean gradient magnitude after a light blur, grey levels per pixel of an eye 1280 px wide
    // (a wider one is reduced to it first), read at the reference exposure when the region is
    // dimmer (health::exposureScale): less light is not less texture to the matcher, whose costs
    // compare grey levels relative to their neighbours, and more pixels are not less texture.
    double contrast = 0;
};

// grey: CV_8U; roi: CV_8U mask (empty = whole image).
ImageQuality measureImageQuality(const cv::Mat& grey, const cv::Mat& roi);

// Why an image is unfit to measure, or nothing. `which` names it ("baseline", "current").
std::optional<std::string> imageProblem(const ImageQuality& quality, const Parameters& parameters,
                                        const std::string& which);

// Why the current capture cannot be measured against the baseline, both measured over the same
// region: clipped white over more of it than the baseline was (maxNewSaturatedPercent).
std::optional<std::string> newSaturationProblem(const ImageQuality& baseline, const ImageQuality& current,
                                                const Parameters& parameters);

}  // namespace icewatch::volume
