// OpenCV StereoSGBM as a baseline. Penalties follow OpenCV's stereo_match sample
// (P1 = 8·cn·block², P2 = 32·cn·block²), the usual way it is compared in the literature.
#include "core/stereo/sgbm_matcher.hpp"

#include <algorithm>
#include <limits>

#include "core/stereo/matcher.hpp"

namespace icewatch::stereo {

SgbmMatcher::SgbmMatcher(const Parameters& parameters) : parameters_(parameters) {}

namespace {

// OpenCV's fixed point: 1/16 px.
constexpr int kSgbmScale = 16;

// Whether a pixel OpenCV matched has its best integer match on the band's edge or outside it,
// from its fixed-point output. OpenCV fits no sub-pixel offset at the first and last disparity it
// searched and writes them as they are; inside, the offset is ((S[d-1] - S[d+1]) * 16 + k) / (2k),
// k = S[d-1] + S[d+1] - 2 S[d], which stays within -7 .. +8 sixteenths of d because S[d] is the
// least. So best match max-1 or beyond reads 16 (max-1) - 7 or more, and best match min (when
// min > 0) or below 16 min + 8 or less, wherever OpenCV's range (a multiple of 16) starts and
// ends.
bool outsideBandInterior(int fixedPoint, DisparityRange range) {
    return fixedPoint >= kSgbmScale * (range.max - 1) - 7 ||
           (range.min > 0 && fixedPoint <= kSgbmScale * range.min + kSgbmScale / 2);
}

}  // namespace

cv::Mat SgbmMatcher::compute(const cv::Mat& left, const cv::Mat& right, DisparityRange range) {
    const int channels = left.channels();
    const int block = parameters_.sgbmBlockSize;
    // SGBM wants the range as a multiple of 16. It matches only the columns from minDisparity +
    // numDisparities on, so the range it searches ends at max (reaching below min when the band is
    // not a multiple of 16): those columns are then the full range [0, max)'s whenever max is a
    // multiple of 16, and never fewer. (Its 3-way mode fails when there are none.)
    const int numDisparities = std::max(16, (range.width() + 15) / 16 * 16);
    const int first = std::max(0, range.max - numDisparities);
    if (first + numDisparities >= left.cols) return cv::Mat(left.size(), CV_32FC1, cv::Scalar(kInvalidDisparity));
    if (!sgbm_) {
        sgbm_ = cv::StereoSGBM::create(first, numDisparities, block);
    }
    sgbm_->setMinDisparity(first);
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
    sgbm_->compute(left, right, fixedPoint);  // CV_16S, disparity × 16; none: below 16 first
    if (!keepBuffers_) releaseBuffers();
    cv::Mat disparity(fixedPoint.size(), CV_32FC1);
    cv::Mat outside(fixedPoint.size(), CV_8UC1, cv::Scalar(0));
    for (int y = 0; y < fixedPoint.rows; ++y) {
        const auto* in = fixedPoint.ptr<short>(y);
        auto* out = disparity.ptr<float>(y);
        auto* notInBand = outside.ptr<std::uint8_t>(y);
        for (int x = 0; x < fixedPoint.cols; ++x) {
            const bool found = in[x] >= kSgbmScale * first;
            notInBand[x] = found && outsideBandInterior(in[x], range) ? 1 : 0;
            out[x] = found && !notInBand[x] ? static_cast<float>(in[x]) / kSgbmScale : kInvalidDisparity;
        }
    }
    if (parameters_.sgbmFillHoles) {
        // OpenCV's holes are filled from real matches; pixels it matched on the band's edge or
        // outside stay invalid: filled, they would be the clamp the band's edge rule refuses.
        fillHolesAlongRows(disparity);
        disparity.setTo(kInvalidDisparity, outside);
    }
    // Left of the band's minimum no right pixel lies in the band: nothing there to fill from.
    disparity.colRange(0, range.min).setTo(kInvalidDisparity);
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
