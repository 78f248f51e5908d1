#pragma once

#include <opencv2/core.hpp>

namespace icewatch::synth {

// How precisely an image pair can fix disparity at all, whatever the matcher: the right image is
// warped by the true disparity, and in every box of the object the one shift that best aligns it
// with the left image is estimated (a Lucas-Kanade step, zero-mean SSD). With the truth known,
// those shifts are pure noise: their scatter is what the images' sensor noise, compression and
// texture leave to any estimator of a box's mean disparity (close to the Cramér-Rao bound
// σ_e / sqrt(N·mean(g²)) when the noise is white).
struct DisparityFloor {
    int boxPx = 0;
    int boxes = 0;                // boxes wholly (90 %) on the object
    double boxSigmaPx = 0;        // scatter of the boxes' shifts
    double boxMeanPx = 0;         // their mean (the truth's own offset, ~0)
    int objectPixels = 0;         // pixels wholly on one surface of the object, seen by both eyes
    double residualSigma = 0;     // grey levels left after the true warp (noise + compression)
    double meanGradientSq = 0;    // mean squared x-derivative of the warped right image
    // σ of the mean disparity over `pixels` object pixels: the box scatter over the number of boxes
    // they make.
    double meanSigmaPx(int pixels) const;
};

// greyLeft, greyRight: CV_8U or CV_32F rectified eyes; trueDisparity: CV_32F, left view, < 0 where
// the pixel is not wholly on the object. Throws InvalidInput on mismatched inputs or a box under
// 5 px.
DisparityFloor measureDisparityFloor(const cv::Mat& greyLeft, const cv::Mat& greyRight, const cv::Mat& trueDisparity,
                                     int boxPx = 31);

}  // namespace icewatch::synth
