// The Census-based matchers as a flat list of stages; each stage lives in its own file
// (stages.hpp lists them). Volumes of 16-bit costs are the only large buffers: the matching cost
// is aggregated in place, then the scanline sum is written to a second volume; the right view's
// pass has a third, which the left view's scanlines then borrow as their scratch (with the
// right-view pass off, the scanline stage keeps its own).
#include "core/stereo/census_matcher.hpp"

#include <opencv2/imgproc.hpp>

namespace icewatch::stereo {

using namespace detail;

namespace {

// The grey image the intensity refinement reads, CV_32FC1, from the cleaned 8-bit grey. Given a
// float input (with its grey after the impulse repair, before smoothing), the float itself
// wherever the cleaning only repaired impulses: those pixels take the repair. Once smoothing has
// touched the image, its noise (a Gaussian starts above 1.7 grey levels) dwarfs the 0.29 of
// rounding, and the smoothed 8-bit grey serves as for 8-bit input. An 8-bit image passed as float
// thus gives the 8-bit path's image exactly.
void intensityImage(const cv::Mat& cleaned, const cv::Mat& floatInput, const cv::Mat& repaired, cv::Mat& out) {
    cleaned.convertTo(out, CV_32F);
    if (floatInput.empty() || cv::norm(cleaned, repaired, cv::NORM_INF) != 0.0) return;
    cv::Mat unchanged;
    cv::compare(cleaned, roundedToEightBits(floatInput), unchanged, cv::CMP_EQ);
    floatInput.copyTo(out, unchanged);
}

}  // namespace

CensusMatcher::CensusMatcher(Method method, const Parameters& parameters)
    : method_(method), parameters_(parameters) {}

void CensusMatcher::releaseBuffers() {
    eyeScratch_[0] = {};
    eyeScratch_[1] = {};
    refinementScratch_ = {};
    costs_ = {};
    scratch_ = {};
    rightCosts_ = {};
    arms_ = {};
    rightArms_ = {};
    floatLeft_.release();
    floatRight_.release();
}

cv::Mat CensusMatcher::compute(const cv::Mat& left, const cv::Mat& right, DisparityRange range) {
    const Parameters& p = parameters_;
    // 0. Colour and grey versions of both eyes (grey input is matched as colour with R = G = B); a
    //    float average is matched on its rounding to 8 bits, all but the intensity refinement.
    const bool floatInput = left.depth() == CV_32F;
    const cv::Mat left8 = roundedToEightBits(left), right8 = roundedToEightBits(right);
    cv::Mat bgrLeft = left8, bgrRight = right8, greyLeft = left8, greyRight = right8;
    if (left.channels() == 1) {
        cv::cvtColor(left8, bgrLeft, cv::COLOR_GRAY2BGR);
        cv::cvtColor(right8, bgrRight, cv::COLOR_GRAY2BGR);
    } else {
        cv::cvtColor(left8, greyLeft, cv::COLOR_BGR2GRAY);
        cv::cvtColor(right8, greyRight, cv::COLOR_BGR2GRAY);
    }
    if (p.impulseThreshold > 0 || p.noiseSmoothingGain > 0.0) {
        // Copies first: the caller's images are not ours to change.
        bgrLeft = bgrLeft.clone();
        bgrRight = bgrRight.clone();
        greyLeft = greyLeft.clone();
        greyRight = greyRight.clone();
    }
    // The band [min, max) is the full range's problem [0, max - min) on the left image's columns
    // min .. W-1 against the right image's 0 .. W-1-min: a left pixel x left of min has no right
    // pixel in the band, and a right pixel at W-min or beyond no left one. Every stage below runs
    // unchanged on those column views; what it needs of whole images (noise, Census codes, edges,
    // Harris' largest response) is computed on the whole images, so the costs are the full
    // range's, cell for cell. Only the buffers of the views' size are allocated.
    const int viewWidth = left.cols - range.min, disparities = range.width();
    const cv::Rect leftView(range.min, 0, viewWidth, left.rows), rightView(0, 0, viewWidth, left.rows);
    costs_.create(viewWidth, left.rows, disparities);

    // 1. Per eye: impulse repair and noise-adaptive smoothing, then what the matching cost needs of
    //    the image. The two eyes run as two tasks side by side (the stages inside run serially
    //    then; their results do not depend on it), in two rounds: the Census band depends on the
    //    noise of both.
    // The Census codes are made row by row in the cost stage (CensusEncoder says why).
    CensusEncoder encoders[2];
    CostInputs leftInputs{{}, {}, {}, nullptr, &encoders[0], leftView.x};
    CostInputs rightInputs{{}, {}, {}, nullptr, &encoders[1], rightView.x};
    double noise[2] = {0.0, 0.0};
    cv::Mat repaired[2];  // float input: grey after the impulse repair, before any smoothing
    auto cleanEye = [&](bool isLeft) {
        cv::Mat& bgr = isLeft ? bgrLeft : bgrRight;
        cv::Mat& grey = isLeft ? greyLeft : greyRight;
        if (p.impulseThreshold > 0) removeImpulses(bgr, grey, p.impulseThreshold, p.impulseRailThreshold);
        if (floatInput) repaired[isLeft ? 0 : 1] = grey.clone();
        // The noise the Census band has to absorb is what the smoothing left.
        const bool bandFollowsNoise = method_ == Method::Paper && p.censusAlphaNoiseGain > 0.0;
        smoothNoise(bgr, grey, p.noiseSmoothingGain, p.noiseGreyPassRange,
                    bandFollowsNoise ? &noise[isLeft ? 0 : 1] : nullptr);
    };
    auto prepareEye = [&](bool isLeft, int alpha) {
        cv::Mat& bgr = isLeft ? bgrLeft : bgrRight;
        cv::Mat& grey = isLeft ? greyLeft : greyRight;
        const cv::Rect& view = isLeft ? leftView : rightView;
        CostInputs& inputs = isLeft ? leftInputs : rightInputs;
        CensusEncoder& encoder = encoders[isLeft ? 0 : 1];
        EyeScratch* scratch = &eyeScratch_[isLeft ? 0 : 1];
        inputs.bgr = bgr(view);
        if (method_ == Method::Paper) {
            // Improved Census: window by gradient (left only: the left pixel decides, the right
            // image carries both codes), edge and corner bits; the gradient term's magnitudes.
            cv::Mat windowMask;
            if (isLeft) windowMask = censusWindowMask(grey, p.censusGradientThreshold, scratch);
            encoder.prepareImproved(grey, edgeCornerBits(grey, p, scratch), alpha, windowMask);
            if (isLeft) inputs.windowMask = windowMask(view);
            inputs.gradient = channelGradientMagnitudes(bgr, scratch)(view);
        } else {
            encoder.prepareMei(grey);
        }
    };
    cv::parallel_for_(cv::Range(0, 2), [&](const cv::Range& r) {
        for (int eye = r.start; eye < r.end; ++eye) cleanEye(eye == 0);
    }, 2);
    // Both eyes' codes with one band, so the eyes must meet here.
    const int alpha = noiseAdaptiveCensusAlpha(p.censusAlpha, p.censusAlphaNoiseGain, noise[0], noise[1]);
    cv::parallel_for_(cv::Range(0, 2), [&](const cv::Range& r) {
        for (int eye = r.start; eye < r.end; ++eye) prepareEye(eye == 0, alpha);
    }, 2);

    // 2. Cross-based support regions of both images (the right one mirrored, so that the right view
    //    is the left view of the mirrored pair and every stage applies to it unchanged).
    const bool ownRightPass = p.rightViewAggregation;
    const cv::Mat viewLeft = bgrLeft(leftView);
    cv::Mat mirroredRight;
    computeCrossArms(viewLeft, p, arms_);
    if (ownRightPass) {
        cv::flip(bgrRight(rightView), mirroredRight, 1);
        computeCrossArms(mirroredRight, p, rightArms_);
        rightCosts_.create(costs_.width, costs_.height, costs_.disparities);
    }

    // 3. Matching cost per pixel and disparity, each row's Census codes made as the row starts.
    //    Each row, as soon as it is complete and while it is still in cache: the right view's
    //    costs read off it, then the first aggregation pass (means along the rows) of both views.
    const bool rowsFirst = p.crossIterations > 0;
    const std::uint16_t invalid = method_ == Method::Paper ? kPaperInvalidCost : kAdCensusInvalidCost;
    const CostRowHook rowDone = [&](int y) {
        if (ownRightPass) rightViewCostsRow(costs_, invalid, rightCosts_, y);
        if (!rowsFirst) return;
        meanAlongRow(arms_, costs_, y);
        if (ownRightPass) meanAlongRow(rightArms_, rightCosts_, y);
    };
    if (method_ == Method::Paper) {
        paperCost(leftInputs, rightInputs, p, costs_, rowDone);
    } else {
        adCensusCost(leftInputs, rightInputs, p, costs_, rowDone);
    }
    if (!keepBuffers_) {
        // Not needed again this pair: given back before the scanlines, where the volumes peak.
        eyeScratch_[0] = {};
        eyeScratch_[1] = {};
    }

    // 4. The right view, when it gets its own pass: the rest of its aggregation, scanlines
    //    (4 directions by default: Parameters explains) with winner-take-all. Run first, so that
    //    the left view's aggregated volume is the one left in scratch_ for the refinement.
    cv::Mat rightDisparity;
    const ScanlinePenalties penalties = scanlinePenalties(p);
    if (ownRightPass) {
        cv::Mat mirroredDisparity;
        aggregateCross(rightArms_, p.crossIterations, rightCosts_, rowsFirst);
        aggregateScanlines(rightCosts_, mirroredRight, penalties, scratch_, p.rightViewScanlineDirections, nullptr,
                           &mirroredDisparity);
        cv::flip(mirroredDisparity, rightDisparity, 1);
        if (!keepBuffers_) {
            rightArms_ = {};
            mirroredRight.release();
        }
    }

    // The rest of the left view's aggregation over its support regions.
    aggregateCross(arms_, p.crossIterations, costs_, rowsFirst);

    // 5. Scanline optimisation along 8 directions, summed into the second volume; winner-take-all
    //    as each pixel's sum is completed (both views from the finished volume, the right one along
    //    its diagonals, when the right view had no pass of its own).
    // The right view's volume is free by now: it lends the scanline pass its scratch.
    cv::Mat disparity;
    if (p.rightViewAggregation) {
        aggregateScanlines(costs_, viewLeft, penalties, scratch_, 8, &rightCosts_, &disparity);
    } else {
        aggregateScanlines(costs_, viewLeft, penalties, scratch_, 8);
        winnerTakesAll(scratch_, disparity, rightDisparity);
    }
    if (!keepBuffers_) {
        // Only the summed volume is read from here on (the discontinuities and the sub-pixel fit):
        // the costs go before the refinement's images are made, where the memory peaked.
        costs_ = {};
        rightCosts_ = {};
    }

    // 6. Outliers: left-right check (occluded or mismatched), region voting, interpolation;
    //    disparity edges moved to the side whose cost is lower.
    cv::Mat labels = leftRightCheck(disparity, rightDisparity, disparities, p.lrMaxDifference);
    regionVoting(arms_, p, disparity, labels);
    interpolateOutliers(disparity, labels);
    if (p.discontinuityAdjustment) adjustDiscontinuities(scratch_, disparity);

    // 7. Sub-pixel: fit on the aggregated cost (the band's edge invalid), back to the whole
    //    image's columns; intensity refinement against pixel locking; Mei's final 3x3 median.
    cv::Mat refined(left.size(), CV_32FC1, cv::Scalar(kInvalidDisparity));
    subpixelRefine(disparity, scratch_, range).copyTo(refined(leftView));
    if (p.subpixelIntensityRefinement) {
        intensityImage(greyLeft, floatInput ? left : cv::Mat(), repaired[0], floatLeft_);
        intensityImage(greyRight, floatInput ? right : cv::Mat(), repaired[1], floatRight_);
        refineSubpixelByIntensity(floatLeft_, floatRight_, p.subpixelWindowRadius, p.subpixelIterations,
                                  static_cast<float>(p.subpixelMaxChange), refined, &refinementScratch_);
    }
    if (p.medianFilter) cv::medianBlur(refined, refined, 3);
    if (!keepBuffers_) releaseBuffers();
    return refined;
}

}  // namespace icewatch::stereo
