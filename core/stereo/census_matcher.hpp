#pragma once

#include <opencv2/core.hpp>

#include "core/stereo/matcher.hpp"
#include "core/stereo/parameters.hpp"
#include "core/stereo/stages.hpp"

namespace icewatch::stereo {

// The Census-based methods, Paper (Wei et al. 2025) and AdCensus (Mei et al. 2011): the same
// stages with a different matching cost. Owns its scratch, allocated once per image size and band
// width, until releaseBuffers(); or, not keeping buffers, each stage's until the stage ends and the
// rest until compute() returns (Matcher::setKeepBuffers).
class CensusMatcher {
public:
    CensusMatcher(Method method, const Parameters& parameters);
    // Inputs already validated (matcher.cpp).
    cv::Mat compute(const cv::Mat& left, const cv::Mat& right, DisparityRange range);
    void releaseBuffers();
    void setKeepBuffers(bool keep) { keepBuffers_ = keep; }

private:
    Method method_;
    Parameters parameters_;
    bool keepBuffers_ = true;
    detail::EyeScratch eyeScratch_[2];  // left, right
    detail::RefinementScratch refinementScratch_;
    detail::CostVolume costs_;
    detail::CostVolume scratch_;
    detail::CrossArms arms_;
    detail::CostVolume rightCosts_;  // the right view's own pass (Parameters::rightViewAggregation)
    detail::CrossArms rightArms_;
    cv::Mat floatLeft_, floatRight_;  // grey eyes in float for the intensity refinement (intensityImage)
};

}  // namespace icewatch::stereo
