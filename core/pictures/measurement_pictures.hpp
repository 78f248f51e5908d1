#pragma once

#include <string>

#include <opencv2/core.hpp>

#include "core/pictures/picture_scale.hpp"
#include "core/volume/chain.hpp"

namespace icewatch::pictures {

// Below this share of the scale the thickness is not coloured: the blade shows through, and the
// colour marks where the ice is.
inline constexpr double kShownThicknessFraction = 0.02;

// A measurement for a person, all CV_8UC3: the rectified left eye with the region's outline;
// the disparity in false colour on the band the matcher searched, with its colour bar (px); the
// thickness coloured over the grey left eye, with its colour bar (mm). A refused measurement
// keeps the left eye and the disparity, the reason written across the top of each picture.
struct MeasurementPictures {
    cv::Mat left, disparity, thickness;
};

MeasurementPictures drawMeasurement(const volume::Surface& current, const volume::VolumeResult& result,
                                    int maxDisparity, const PictureScale& scale);

// The disparity (CV_32F, px, negative = none) on the band [minDisparity, maxDisparity) the matcher
// searched, with the region's outline when one is given, and its colour bar.
cv::Mat disparityPicture(const cv::Mat& disparity, int minDisparity, int maxDisparity, const cv::Mat& region = {});

// The thickness (CV_32F, mm, NaN where none, pixels of `leftGrey`) over the grey left eye (CV_8U),
// 0 .. maxThicknessMm, with the region's outline and the colour bar.
cv::Mat thicknessPicture(const cv::Mat& leftGrey, const cv::Mat& thicknessMm, const cv::Mat& region,
                         double maxThicknessMm);

}  // namespace icewatch::pictures
