// The Census-based matchers as a flat list of stages; each stage lives in its own file
// (stages.hpp lists them). Two volumes of 16-bit costs are the only large buffers: the matching
// cost is aggregated in place (with the second volume as scratch), then the scanline sum is
// written to the second volume.
#include "core/stereo/census_matcher.hpp"

#include <opencv2/imgproc.hpp>

namespace icewatch::stereo {

using namespace detail;

CensusMatcher::CensusMatcher(Method method, const Parameters& parameters)
    : method_(method), parameters_(parameters) {}

cv::Mat CensusMatcher::compute(const cv::Mat& left, const cv::Mat& right, int maxDisparity) {
    const Parameters& p = parameters_;
    // 0. Colour and grey versions of both eyes (grey input is matched as colour with R = G = B);
    //    impulse noise repaired.
    cv::Mat bgrLeft = left, bgrRight = right, greyLeft = left, greyRight = right;
    if (left.channels() == 1) {
        cv::cvtColor(left, bgrLeft, cv::COLOR_GRAY2BGR);
        cv::cvtColor(right, bgrRight, cv::COLOR_GRAY2BGR);
    } else {
        cv::cvtColor(left, greyLeft, cv::COLOR_BGR2GRAY);
        cv::cvtColor(right, greyRight, cv::COLOR_BGR2GRAY);
    }
    if (p.impulseThreshold > 0) {
        // Copies first: the caller's images are not ours to change.
        bgrLeft = bgrLeft.clone();
        bgrRight = bgrRight.clone();
        greyLeft = greyLeft.clone();
        greyRight = greyRight.clone();
        removeImpulses(bgrLeft, greyLeft, p.impulseThreshold);
        removeImpulses(bgrRight, greyRight, p.impulseThreshold);
    }
    costs_.create(left.cols, left.rows, maxDisparity);

    // 1. Matching cost per pixel and disparity.
    CostInputs leftInputs{bgrLeft, {}, {}, &leftCensus_};
    CostInputs rightInputs{bgrRight, {}, {}, &rightCensus_};
    if (method_ == Method::Paper) {
        // Improved Census: window by gradient (left only: the left pixel decides, the right
        // image carries both codes), edge and corner bits, then AD and gradient terms.
        leftInputs.windowMask = censusWindowMask(greyLeft, p.censusGradientThreshold);
        improvedCensus(greyLeft, edgeCornerBits(greyLeft, p), p.censusAlpha, leftInputs.windowMask, leftCensus_);
        improvedCensus(greyRight, edgeCornerBits(greyRight, p), p.censusAlpha, cv::Mat(), rightCensus_);
        leftInputs.gradient = channelGradientMagnitudes(bgrLeft);
        rightInputs.gradient = channelGradientMagnitudes(bgrRight);
        paperCost(leftInputs, rightInputs, p, costs_);
    } else {
        meiCensus(greyLeft, leftCensus_);
        meiCensus(greyRight, rightCensus_);
        adCensusCost(leftInputs, rightInputs, p, costs_);
    }

    // 2. Cross-based support regions of the left image; aggregation over them.
    computeCrossArms(bgrLeft, p, arms_);
    aggregateCross(arms_, p.crossIterations, costs_, scratch_);

    // 3. Scanline optimisation along 8 directions, summed into the second volume.
    aggregateScanlines(costs_, bgrLeft, scanlinePenalties(p), scratch_);

    // 4. Winner-take-all, left and right views.
    cv::Mat disparity, rightDisparity;
    winnerTakesAll(scratch_, disparity, rightDisparity);

    // 5. Outliers: left-right check (occluded or mismatched), region voting, interpolation;
    //    disparity edges moved to the side whose cost is lower.
    cv::Mat labels = leftRightCheck(disparity, rightDisparity, maxDisparity, p.lrMaxDifference);
    regionVoting(arms_, p, disparity, labels);
    interpolateOutliers(disparity, labels);
    if (p.discontinuityAdjustment) adjustDiscontinuities(scratch_, disparity);

    // 6. Sub-pixel: fit on the aggregated cost, intensity refinement against pixel locking;
    //    Mei's final 3x3 median.
    cv::Mat refined = subpixelRefine(disparity, scratch_);
    if (p.subpixelIntensityRefinement) {
        cv::Mat floatLeft, floatRight;
        greyLeft.convertTo(floatLeft, CV_32F);
        greyRight.convertTo(floatRight, CV_32F);
        refineSubpixelByIntensity(floatLeft, floatRight, p.subpixelWindowRadius, p.subpixelIterations,
                                  static_cast<float>(p.subpixelMaxChange), refined);
    }
    if (p.medianFilter) cv::medianBlur(refined, refined, 3);
    return refined;
}

}  // namespace icewatch::stereo
