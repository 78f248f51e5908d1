// The object inside a hand-drawn outline (drawn_outline.hpp).
#include "core/volume/drawn_outline.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "core/volume/mask_parts.hpp"
#include "core/volume/patch_tracker.hpp"
#include "core/volume/robust_statistics.hpp"

namespace icewatch::volume {

namespace {

// Pixels this far from the background the flood reached may still be background: the 5 x 5
// spread rises within two pixels of the object's edge and the smoothing spreads the edge by one
// or two more.
constexpr int kEdgeReachPx = 4;
// Less background than this inside the drawn outline is the rasterised edge's fringe, not a margin.
constexpr int kMinBackgroundPixels = 25;
// The ring outside the drawn outline whose look says what it was drawn over.
constexpr int kRingPx = 6;

// The values of `values` (CV_32F) where `where` (CV_8U) is set.
std::vector<float> valuesWhere(const cv::Mat& values, const cv::Mat& where) {
    std::vector<float> v;
    for (int y = 0; y < values.rows; ++y) {
        const float* d = values.ptr<float>(y);
        const auto* in = where.ptr<std::uint8_t>(y);
        for (int x = 0; x < values.cols; ++x)
            if (in[x]) v.push_back(d[x]);
    }
    return v;
}

}  // namespace

DrawnOutline objectInDrawnOutline(const cv::Mat& drawn, const cv::Mat& grey, double minTextureGrey,
                                  double minContrastGrey) {
    CV_Assert(drawn.type() == CV_8UC1 && grey.type() == CV_32FC1 && drawn.size() == grey.size());
    DrawnOutline out;
    out.object = drawn.clone();
    const int drawnPixels = cv::countNonZero(drawn);
    if (drawnPixels == 0) return out;
    const cv::Mat pictured = grey > 0.0f;

    // Featureless: the 5 x 5 spread of the smoothed picture, over pictured pixels only.
    cv::Mat smooth;
    cv::GaussianBlur(grey, smooth, {0, 0}, kTrackingSmoothingPx, kTrackingSmoothingPx, cv::BORDER_REFLECT);
    const cv::Mat mean = localMean(smooth, pictured, 2);
    const cv::Mat meanSquare = localMean(smooth.mul(smooth), pictured, 2);
    cv::Mat featureless(grey.size(), CV_8U, cv::Scalar(0));
    for (int y = 0; y < grey.rows; ++y) {
        const float* m = mean.ptr<float>(y);
        const float* m2 = meanSquare.ptr<float>(y);
        const auto* p = pictured.ptr<std::uint8_t>(y);
        auto* f = featureless.ptr<std::uint8_t>(y);
        for (int x = 0; x < grey.cols; ++x) {
            if (!p[x] || std::isnan(m[x])) continue;
            const double variance = std::max(0.0, double(m2[x]) - double(m[x]) * double(m[x]));
            if (std::sqrt(variance) < minTextureGrey) f[x] = 255;
        }
    }
    // The background the outline was drawn over: the pictured ring just outside it. Only a
    // featureless one (the sky) is taken out: a textured one (a table) the trackers and the
    // matcher measure, and the chain reads it as the clean surface it is.
    cv::Mat ring;
    cv::dilate(drawn, ring, cv::getStructuringElement(cv::MORPH_RECT, {2 * kRingPx + 1, 2 * kRingPx + 1}));
    ring &= pictured & ~drawn;
    const cv::Mat ringFeatureless = ring & featureless;
    const int ringFeaturelessPixels = cv::countNonZero(ringFeatureless);
    if (ringFeaturelessPixels == 0 || 2 * ringFeaturelessPixels < cv::countNonZero(ring)) return out;
    // Its brightness: where the outline cuts across the object, the ring is the object's, and a
    // featureless part of it must not lead the flood into the object.
    const cv::Mat residual = grey - smooth;
    const double noise = spreadAboutZero(valuesWhere(residual, ringFeatureless));
    const double backgroundLevel = median(valuesWhere(smooth, ringFeatureless));
    const cv::Mat offset = smooth - backgroundLevel;
    const double spread = spreadAboutZero(valuesWhere(offset, ringFeatureless));
    const float tolerance = static_cast<float>(std::max({minContrastGrey, 4.0 * noise, 3.0 * spread}));
    const cv::Mat likeBackground = featureless & (cv::abs(offset) <= tolerance);
    // The background is what it reaches from outside the outline without crossing texture or an edge.
    cv::Mat background = partsHolding(likeBackground, likeBackground & ringFeatureless);
    if (cv::countNonZero(background & drawn) < kMinBackgroundPixels) return out;

    // Up to the object's edge: a pixel beside the background whose grey is the background's.
    const cv::Mat cross = cv::getStructuringElement(cv::MORPH_RECT, {3, 3});
    for (int step = 0; step < kEdgeReachPx; ++step) {
        const cv::Mat level = localMean(grey, background, 3);
        cv::Mat next;
        cv::dilate(background, next, cross);
        next &= pictured & ~background;
        bool grew = false;
        for (int y = 0; y < grey.rows; ++y) {
            const float* g = grey.ptr<float>(y);
            const float* l = level.ptr<float>(y);
            auto* n = next.ptr<std::uint8_t>(y);
            auto* b = background.ptr<std::uint8_t>(y);
            for (int x = 0; x < grey.cols; ++x) {
                if (!n[x] || std::isnan(l[x]) || std::abs(g[x] - l[x]) > tolerance) continue;
                b[x] = 255;
                grew = true;
            }
        }
        if (!grew) break;
    }

    // What is left of the object is its parts that hold some of it, not specks the flood went round.
    const cv::Mat object = largeParts(drawn & ~background, kSpeckShareOfLargest);
    if (cv::countNonZero(object) == 0) return out;  // all of it looks like background: leave the outline as drawn
    out.backgroundPercent = 100.0 * (drawnPixels - cv::countNonZero(object)) / drawnPixels;
    out.object = object;
    return out;
}

}  // namespace icewatch::volume
