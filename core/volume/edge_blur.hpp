#pragma once

#include <optional>

#include <opencv2/core.hpp>

namespace icewatch::volume {

// How blurred a capture is, read off the object's outline. A lens out of focus, a renderer's pixel
// filter or a misted window spread every edge the camera sees alike, the ice's steps as much as
// the outline; stereo carries a step's nearer disparity over the surface beside it about as far
// as the step is spread, so the fattening the uncertainty allows grows with the blur
// (uncertainty.hpp). The outline is the one edge whose place is known: the object against its
// background, sky or table.

struct EdgeBlurOptions {
    int stationStepPx = 4;
    double halfLengthPx = 8.0;   // each profile across the outline, in and out
    double minStepGrey = 20.0;   // the object against its background by at least this
    int minStations = 30;
};

// What a step as sharp as the pixels reads: 0.4-0.8 with its place on the pixel grid, 0.55-0.61
// along the outlines of sharp rendered blades.
inline constexpr double kPixelSharpBlurPx = 0.7;

// The blur beyond the pixels' own, px: sqrt(measured^2 - kPixelSharpBlurPx^2), 0 when sharper.
double blurBeyondPixelsPx(double measuredPx);

// The blur's sigma, px: of the Gaussian that spreads a step as the outline is spread (the step's
// height over its steepest slope, over sqrt(2 pi)), the median over the stations where the object
// stands against its background by minStepGrey; nullopt with fewer such stations. A step as sharp
// as the pixels reads about 0.4 (the pixels' own box).
// `grey`: the left eye (CV_32F); `roi`: the object (CV_8U); `valid`: where the image holds pixels.
std::optional<double> outlineBlurPx(const cv::Mat& grey, const cv::Mat& roi, const cv::Rect& valid,
                                    const EdgeBlurOptions& options = {});

}  // namespace icewatch::volume
