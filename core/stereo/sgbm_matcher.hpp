#pragma once

#include <opencv2/calib3d.hpp>

#include "core/stereo/matcher.hpp"
#include "core/stereo/parameters.hpp"

namespace icewatch::stereo {

// OpenCV's StereoSGBM in 3-way mode, wrapped so it answers like our own methods: CV_32F
// disparities in pixels, kInvalidDisparity where it found none (or holes filled on request) and
// on the band's edge (DisparityRange).
class SgbmMatcher {
public:
    explicit SgbmMatcher(const Parameters& parameters);
    // 8-bit inputs already validated (matcher.cpp rounds float ones).
    cv::Mat compute(const cv::Mat& left, const cv::Mat& right, DisparityRange range);
    void releaseBuffers() { sgbm_.release(); }  // OpenCV's matcher keeps its buffer
    void setKeepBuffers(bool keep) { keepBuffers_ = keep; }

private:
    Parameters parameters_;
    bool keepBuffers_ = true;
    cv::Ptr<cv::StereoSGBM> sgbm_;
};

// Fills each invalid pixel from the nearer valid neighbour on its row, taking the smaller
// (background) disparity when both sides are valid. Used to compare with methods that leave no
// holes.
void fillHolesAlongRows(cv::Mat& disparity);

}  // namespace icewatch::stereo
