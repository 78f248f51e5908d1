// OpenCV StereoSGBM as a baseline. Penalties follow OpenCV's stereo_match sample
// (P1 = 8·cn·block², P2 = 32·cn·block²), the usual way it is compared in the literature.
#include "core/stereo/sgbm_matcher.hpp"

#include <algorithm>
#include <limits>

#include "core/stereo/matcher.hpp"

namespace icewatch::stereo {

SgbmMatcher::SgbmMatcher(const Parameters& parameters) : parameters_(parameters) {}

cv::Mat SgbmMatcher::compute(const cv::Mat& left, const cv::Mat& right, int maxDisparity) {
    const int channels = left.channels();
    const int block = parameters_.sgbmBlockSize;
    // SGBM wants the range as a multiple of 16.
    const int numDisparities = std::max(16, (maxDisparity + 15) / 16 * 16);
    if (!sgbm_) {
        sgbm_ = cv::StereoSGBM::create(0, numDisparities, block);
    }
    sgbm_->setNumDisparities(numDisparities);
    sgbm_->setBlockSize(block);
    sgbm_->setP1(8 * channels * block * block);
    sgbm_->setP2(32 * channels * block * block);
    sgbm_->setMode(cv::StereoSGBM::MODE_SGBM_3WAY);
    sgbm_->setUniquenessRatio(10);
    sgbm_->setSpeckleWindowSize(100);
    sgbm_->setSpeckleRange(2);
    sgbm_->setDisp12MaxDiff(1);

    cv::Mat fixedPoint;
    sgbm_->compute(left, right, fixedPoint);  // CV_16S, disparity × 16, negative = invalid
    cv::Mat disparity(fixedPoint.size(), CV_32FC1);
    for (int y = 0; y < fixedPoint.rows; ++y) {
        const auto* in = fixedPoint.ptr<short>(y);
        auto* out = disparity.ptr<float>(y);
        for (int x = 0; x < fixedPoint.cols; ++x) {
            const float d = in[x] / 16.0f;
            out[x] = (in[x] < 0 || d >= static_cast<float>(maxDisparity)) ? kInvalidDisparity : d;
        }
    }
    if (parameters_.sgbmFillHoles) {
        fillHolesAlongRows(disparity);
    }
    return disparity;
}

void fillHolesAlongRows(cv::Mat& disparity) {
    CV_Assert(disparity.type() == CV_32FC1);
    const int width = disparity.cols;
    std::vector<float> leftValid(static_cast<std::size_t>(width));
    for (int y = 0; y < disparity.rows; ++y) {
        auto* row = disparity.ptr<float>(y);
        float last = kInvalidDisparity;
        for (int x = 0; x < width; ++x) {
            if (row[x] >= 0.0f) last = row[x];
            leftValid[static_cast<std::size_t>(x)] = last;
        }
        float next = kInvalidDisparity;
        for (int x = width - 1; x >= 0; --x) {
            if (row[x] >= 0.0f) {
                next = row[x];
                continue;
            }
            const float l = leftValid[static_cast<std::size_t>(x)];
            if (l >= 0.0f && next >= 0.0f) {
                row[x] = std::min(l, next);
            } else if (l >= 0.0f) {
                row[x] = l;
            } else if (next >= 0.0f) {
                row[x] = next;
            }
        }
    }
}

}  // namespace icewatch::stereo
