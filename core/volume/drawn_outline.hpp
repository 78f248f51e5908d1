#pragma once

#include <opencv2/core.hpp>

namespace icewatch::volume {

// The object inside an outline drawn around it by hand (roi.json, volume.roi_polygon).
struct DrawnOutline {
    cv::Mat object;                // CV_8U, 255 on the object: the drawn outline less the background in it
    double backgroundPercent = 0;  // of the drawn outline, what was found to be background and left out
};

// An outline drawn at commissioning is rarely the object's edge: drawn around a blade against the
// sky it holds a margin of sky, whose featureless pixels the matcher fills with whatever depth is
// beside them. Measured as object, that margin reads the ice's depth beside the ice as ice (drawn
// 20 px wide of a rendered blade, the chain said `ok` at +52 % outside its uncertainty; 4 px wide
// +19 %), and every stage that looks beyond the outline looks in the wrong place.
//
// So the background is taken out of it: featureless pixels of the baseline's left eye (their 5 x 5
// spread under minTextureGrey, on the trackers' smoothed image) connected to the featureless
// background outside the drawn outline are background, and so are the pixels next to them, up to
// the object's edge, whose grey stays within the background's around them (minContrastGrey, or
// four times its noise). An object whose own surface is featureless where it meets the background
// looks like it and may lose that part; an outline drawn on the object's edge, or over a textured
// background (a table), comes back as drawn.
//
// drawn: CV_8U mask; grey: CV_32F, the capture's left eye, 0 where no picture was taken.
DrawnOutline objectInDrawnOutline(const cv::Mat& drawn, const cv::Mat& grey, double minTextureGrey,
                                  double minContrastGrey);

}  // namespace icewatch::volume
