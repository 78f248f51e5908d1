// Ice beyond the outline (beyond_outline.hpp).
#include "core/volume/beyond_outline.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/imgproc.hpp>

#include "core/volume/mask_parts.hpp"

namespace icewatch::volume {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// `region` dilated by a disc of `radiusPx` over `reach` only (region itself for 0).
cv::Mat grown(const cv::Mat& region, const cv::Rect& reach, int radiusPx) {
    cv::Mat out;
    if (radiusPx <= 0) return region(reach).clone();
    cv::dilate(region(reach), out, cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * radiusPx + 1, 2 * radiusPx + 1}));
    return out;
}

// `mask` (CV_8U, on the grid) grown by the ring's gap of gapNodes next to the region and a node
// more: what touches it across the unmeasured nodes between the outline and the ring.
cv::Mat acrossTheGap(const cv::Mat& mask, int gapNodes) {
    cv::Mat out;
    cv::dilate(mask, out, cv::getStructuringElement(cv::MORPH_RECT, {2 * gapNodes + 3, 2 * gapNodes + 3}));
    return out;
}

}  // namespace

int outlineGrowthPx(const Parameters& p, double focalPx, double depthMm) {
    if (p.outlineGrowthMm <= 0 || !(depthMm > 0)) return 0;
    return static_cast<int>(std::ceil(p.outlineGrowthMm * focalPx / depthMm));
}

cv::Mat outlineRing(const cv::Mat& region, int growthPx, int skipPx) {
    CV_Assert(region.type() == CV_8UC1);
    cv::Mat ring = cv::Mat::zeros(region.size(), CV_8U);
    if (growthPx <= 0 || skipPx >= growthPx) return ring;
    // The dilation over the region's box and the growth's reach only, as the ice mask does.
    const cv::Rect box = cv::boundingRect(region);
    const cv::Rect reach = (box + cv::Size(2 * growthPx, 2 * growthPx) - cv::Point(growthPx, growthPx)) &
                           cv::Rect({0, 0}, region.size());
    if (reach.empty()) return ring;
    cv::Mat part = ring(reach);
    part.setTo(255, grown(region, reach, growthPx) & ~grown(region, reach, skipPx));
    return ring;
}

namespace {

// Zero-mean normalised correlation of the left patch at (x, y) with the right one at (x - d, y),
// the right image read linearly between its pixels; NaN where the left patch's deviation is under
// minDeviation or either patch leaves its image.
double eyesCorrelation(const TrackingImage& left, const TrackingImage& right, int x, int y, double d,
                       double minDeviation) {
    const int r = kRingPatchRadiusPx;
    const int lx = x - left.origin.x, ly = y - left.origin.y;
    const double rx = x - d - right.origin.x;
    const int ry = y - right.origin.y;
    const int rx0 = static_cast<int>(std::floor(rx));
    const double t = rx - rx0;
    if (lx - r < 0 || ly - r < 0 || lx + r >= left.grey.cols || ly + r >= left.grey.rows) return kNaN;
    if (rx0 - r < 0 || ry - r < 0 || rx0 + r + 1 >= right.grey.cols || ry + r >= right.grey.rows) return kNaN;
    double sa = 0, sb = 0, saa = 0, sbb = 0, sab = 0;
    for (int j = -r; j <= r; ++j) {
        const auto* a = left.grey.ptr<float>(ly + j);
        const auto* b = right.grey.ptr<float>(ry + j);
        for (int i = -r; i <= r; ++i) {
            const double va = a[lx + i];
            const double vb = (1.0 - t) * b[rx0 + i] + t * b[rx0 + i + 1];
            sa += va;
            sb += vb;
            saa += va * va;
            sbb += vb * vb;
            sab += va * vb;
        }
    }
    const double n = (2 * r + 1) * (2 * r + 1);
    const double va = saa - sa * sa / n, vb = sbb - sb * sb / n;
    if (va < minDeviation * minDeviation * n || vb <= 0) return kNaN;
    return (sab - sa * sb / n) / std::sqrt(va * vb);
}

}  // namespace

cv::Mat measurableRing(const RectifiedCapture& capture, const cv::Mat& ring, const Parameters& p) {
    CV_Assert(ring.type() == CV_8UC1 && capture.disparity.size() == ring.size());
    cv::Mat measurable = cv::Mat::zeros(ring.size(), CV_8U);
    const cv::Rect box = cv::boundingRect(ring);
    if (box.empty() || capture.left.empty() || capture.right.empty()) return measurable;
    cv::Mat failed = cv::Mat::zeros(ring.size(), CV_8U);
    // Each row on its own: the same mask whatever the thread count.
    cv::parallel_for_(cv::Range(box.y, box.y + box.height), [&](const cv::Range& rows) {
        for (int y = rows.start; y < rows.end; ++y) {
            const auto* inRing = ring.ptr<std::uint8_t>(y);
            const auto* d = capture.disparity.ptr<float>(y);
            for (int x = box.x; x < box.x + box.width; ++x) {
                if (!inRing[x]) continue;
                const double c = d[x] > 0 ? eyesCorrelation(capture.left, capture.right, x, y, d[x], p.outlineMinTextureGrey)
                                          : kNaN;
                if (c >= p.outlineMinCorrelation) measurable.at<std::uint8_t>(y, x) = 255;
                else failed.at<std::uint8_t>(y, x) = 255;
            }
        }
    });
    // A patch astride the silhouette of what stands against featureless sky reads the edge in both
    // eyes and passes, while its centre is sky that the matcher gave the object's depth.
    cv::Mat reach;
    cv::dilate(failed, reach, cv::getStructuringElement(cv::MORPH_RECT, {2 * kRingPatchRadiusPx + 1, 2 * kRingPatchRadiusPx + 1}));
    measurable.setTo(0, reach);
    return measurable;
}

cv::Mat iceBeyondOutline(const cv::Mat& riseMm, const cv::Mat& inside, double minRiseMm, int gapNodes,
                         double floorMm) {
    CV_Assert(riseMm.type() == CV_64FC1 && inside.type() == CV_8UC1 && riseMm.size() == inside.size());
    const cv::Mat rising = (riseMm > floorMm) & (inside == 0);  // NaN compares false
    // What lies within the gap of the region (and next to it).
    const cv::Mat near = acrossTheGap(inside, gapNodes);
    // Of the parts that touch the region, those that rise somewhere by minRiseMm.
    const cv::Mat touching = partsHolding(rising, near, 4);
    cv::Mat ice = partsHolding(touching, touching & (riseMm >= minRiseMm), 4);
    if (gapNodes > 0) {
        // The gap between the region and the ice touching it: unmeasured nodes near both.
        const cv::Mat unmeasured = ~(riseMm == riseMm);  // NaN != NaN
        ice.setTo(255, near & acrossTheGap(ice, gapNodes) & (inside == 0) & unmeasured);
    }
    return ice;
}

int iceAtRingEdge(const cv::Mat& beyond, const cv::Mat& tapered, const cv::Mat& thicknessMm, const cv::Mat& inside,
                  const cv::Mat& ringEdge, double minRiseMm, int gapNodes) {
    CV_Assert(beyond.type() == CV_8UC1 && inside.type() == CV_8UC1 && ringEdge.type() == CV_8UC1 &&
              thicknessMm.type() == CV_64FC1 && beyond.size() == inside.size() && ringEdge.size() == inside.size() &&
              thicknessMm.size() == inside.size() && (tapered.empty() || tapered.size() == inside.size()));
    // What the background it hides shows there, or a rise of twice what counts as ice: a part
    // counted for touching ice nearer the object runs out at the noise's level, and the edge holds
    // hundreds of nodes. A rendered blade on a table moved 15 mm had 11 edge nodes at one
    // threshold (4 sigma of the ring's rise), one at 1.5 and none at twice it; icicles reaching
    // past the ring on a table, 89 to 168 nodes at twice it (all the way from the outline, below)
    // at 97 609 mm3 and more, none at 15 000-40 000 (needles there: +64 to -21 %, inside), and
    // against the sky the background they hide.
    cv::Mat standing = beyond & (thicknessMm >= 2.0 * minRiseMm);
    if (!tapered.empty()) standing |= tapered;
    // And standing so all the way from the outline: ice hanging from the object is thickest where
    // it grows from it, while a lone spike of the rise's error out at the ring's edge is not (a
    // rendered blade on a table, moved 17 mm and rolled 25°, held two such nodes of 4.7 mm on
    // ~1 mm of noise touching the outline, and was refused where it read +0.9 %). The gap between
    // the outline and the ring is not measured: a part within it touches.
    return cv::countNonZero(partsHolding(standing, acrossTheGap(inside, gapNodes)) & ringEdge);
}

cv::Mat taperedIce(const cv::Mat& hidden, const cv::Mat& inside, const cv::Mat& edgeThicknessMm, double minThicknessMm,
                   int gapNodes, cv::Mat& thickness, cv::Mat* thinMm) {
    CV_Assert(hidden.type() == CV_8UC1 && inside.type() == CV_8UC1 && hidden.size() == inside.size());
    if (thinMm) CV_Assert(thinMm->type() == CV_64FC1 && thinMm->size() == inside.size());
    CV_Assert(edgeThicknessMm.type() == CV_64FC1 && edgeThicknessMm.size() == inside.size());
    CV_Assert(thickness.type() == CV_64FC1 && thickness.size() == inside.size());
    // The nodes between the region and what hides the background, up to gapNodes wide, stand too;
    // but not the notches the closing fills in the region's own outline (a slanted outline is a
    // staircase on the grid), where nothing hid the background: the region is closed alike first.
    cv::Mat closed = inside | hidden, region = inside.clone();
    if (gapNodes > 0) {
        const cv::Mat square = cv::getStructuringElement(cv::MORPH_RECT, {2 * gapNodes + 1, 2 * gapNodes + 1});
        cv::morphologyEx(closed, closed, cv::MORPH_CLOSE, square);
        cv::morphologyEx(region, region, cv::MORPH_CLOSE, square);
    }
    const cv::Mat candidate = closed & (region == 0);
    cv::Mat near;
    cv::dilate(region, near, cv::getStructuringElement(cv::MORPH_RECT, {3, 3}));
    const cv::Mat standing = partsHolding(candidate, near);
    // Node distances to the region and to the background; the outline and the silhouette lie half
    // a node beyond the last node on either side.
    cv::Mat toRegion, toBackground;
    cv::distanceTransform(region == 0, toRegion, cv::DIST_L2, cv::DIST_MASK_PRECISE);
    cv::distanceTransform(region | standing, toBackground, cv::DIST_L2, cv::DIST_MASK_PRECISE);
    cv::Mat ice = cv::Mat::zeros(inside.size(), CV_8U);
    for (int j = 0; j < inside.rows; ++j)
        for (int i = 0; i < inside.cols; ++i) {
            if (!standing.at<std::uint8_t>(j, i)) continue;
            const double height = edgeThicknessMm.at<double>(j, i);
            const double in = toRegion.at<float>(j, i) - 0.5, out = toBackground.at<float>(j, i) - 0.5;
            const double t = in / std::max(1e-9, in + out);
            if (!(height >= minThicknessMm)) {
                if (thinMm) thinMm->at<double>(j, i) = minThicknessMm * (1.0 - t * t);
                continue;
            }
            thickness.at<double>(j, i) = height * (1.0 - t * t);
            ice.at<std::uint8_t>(j, i) = 255;
        }
    return ice;
}

cv::Mat widthAcrossMm(const cv::Mat& parts, double cellMm) {
    CV_Assert(parts.type() == CV_8UC1 && cellMm > 0);
    // Nodes to the nearest node outside the parts (the disc's radius is half a node less); past the
    // grid's edge is outside too, so that a part filling the grid still ends somewhere.
    cv::Mat padded, toOutside, neighbours;
    cv::copyMakeBorder(parts, padded, 1, 1, 1, 1, cv::BORDER_CONSTANT, cv::Scalar(0));
    cv::distanceTransform(padded, toOutside, cv::DIST_L2, cv::DIST_MASK_PRECISE);
    toOutside = toOutside(cv::Rect(1, 1, parts.cols, parts.rows));
    // The largest discs are centred on the parts' spine, where no neighbour's distance exceeds the
    // node's own: they are painted over the nodes they cover; every node keeps at least its own.
    cv::dilate(toOutside, neighbours, cv::getStructuringElement(cv::MORPH_RECT, {3, 3}));
    cv::Mat radius(parts.size(), CV_32F, cv::Scalar(0));
    for (int j = 0; j < parts.rows; ++j)
        for (int i = 0; i < parts.cols; ++i) {
            const float own = toOutside.at<float>(j, i);
            if (!(own > 0)) continue;
            const float r = own - 0.5f;
            radius.at<float>(j, i) = std::max(radius.at<float>(j, i), r);
            if (neighbours.at<float>(j, i) > own) continue;
            const int reach = static_cast<int>(std::floor(r));
            for (int y = std::max(0, j - reach); y <= std::min(parts.rows - 1, j + reach); ++y)
                for (int x = std::max(0, i - reach); x <= std::min(parts.cols - 1, i + reach); ++x) {
                    if (float(std::hypot(x - i, y - j)) > r || !parts.at<std::uint8_t>(y, x)) continue;
                    radius.at<float>(y, x) = std::max(radius.at<float>(y, x), r);
                }
        }
    cv::Mat width;
    radius.convertTo(width, CV_64F, 2.0 * cellMm);
    return width;
}

}  // namespace icewatch::volume
