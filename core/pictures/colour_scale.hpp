#pragma once

#include <string>

#include <opencv2/core.hpp>

namespace icewatch::pictures {

// A fixed scale for false-colour pictures: the same value gets the same colour in every picture,
// so two days can be compared. Values outside [lo, hi] get the end colours.
struct ColourScale {
    double lo = 0.0;
    double hi = 1.0;
    std::string unit;   // "mm", "px": written above the colour bar
    std::string title;  // "thickness", "disparity"
};

// The colour of one value on the scale (OpenCV's Turbo map, 256 steps). BGR.
cv::Vec3b colourOf(double value, const ColourScale& scale);

// False colour of a one-channel CV_32F or CV_64F map: NaN and infinity are "no value" and black.
// CV_8UC3. This is the one colour map of the project.
cv::Mat falseColour(const cv::Mat& values, const ColourScale& scale);

// Where withColourBar() puts the bar itself (the gradient, top = hi, bottom = lo) in the picture
// it returns, for a picture of `imageSize`.
cv::Rect colourBarRect(cv::Size imageSize);

// The picture with a strip on its right: the scale's title and unit, the gradient from lo (bottom)
// to hi (top) and the values at both ends and the middle. CV_8UC3 in and out.
cv::Mat withColourBar(const cv::Mat& picture, const ColourScale& scale);

}  // namespace icewatch::pictures
