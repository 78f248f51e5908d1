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

// How far around the outline the object's edge is looked for when the outline stands on none.
inline constexpr int kMaxEdgeSearchPx = 32;

// The blur read off the outline (outlineBlurPx) or, where the outline stands on no step, off the
// edge around it: the outline grown by halfLengthPx at a time, up to kMaxEdgeSearchPx, each
// profile cut around its steepest rise, and the growth whose stations see a step most often taken.
// An outline may be drawn inside the object's edge (a plate's, kept off its rim); read as none,
// the blur was taken for the pixels' own, and a capture blurred by 1.75 px lost the fattening its
// steps carry (a rendered block of 150 000 mm³ read +21.3 % within ±63 023 mm³; its edge, found,
// reads 1.81 px, and the same +21.3 % within ±105 177).
std::optional<double> objectBlurPx(const cv::Mat& grey, const cv::Mat& roi, const cv::Rect& valid,
                                   const EdgeBlurOptions& options = {});

}  // namespace icewatch::volume
