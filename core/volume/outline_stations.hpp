#pragma once

#include <vector>

#include <opencv2/core.hpp>

namespace icewatch::volume {

// Places along the object's outline where a profile across it is read (outline_growth.hpp,
// edge_blur.hpp): every `stepPx` along the region's outer contour, with the outline's outward
// normal there. Corners, where the normal does not lead out of the region, are left out.
struct OutlineStation {
    cv::Point2d at;
    cv::Point2d outward;  // unit
};
std::vector<OutlineStation> outlineStations(const cv::Mat& roi, int stepPx);

// Whether the mask (CV_8U) is set at the pixel nearest `at`; false outside it.
bool insideMask(const cv::Mat& mask, cv::Point2d at);

// The grey (CV_32F image) along `normal` through `centre`, from `insidePx` in to `outsidePx` out
// every `stepPx`, each sample the mean of three lines a pixel apart along the outline (bilinear);
// empty when any sample leaves `valid`.
std::vector<float> profileAcross(const cv::Mat& image, const cv::Rect& valid, cv::Point2d centre, cv::Point2d normal,
                                 double insidePx, double outsidePx, double stepPx);

}  // namespace icewatch::volume
