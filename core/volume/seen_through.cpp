// Ice through which the object's own texture was seen (seen_through.hpp).
#include "core/volume/seen_through.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/imgproc.hpp>

#include "core/volume/height_grid.hpp"
#include "core/volume/thickness_map.hpp"

namespace icewatch::volume {

namespace {

// Whether any of the eight samples around `at` (stepPx apart) found the object's texture again
// unchanged: `unchanged` marks them (CV_8U, 255, over `box`).
bool besideUnchanged(const cv::Mat& unchanged, const cv::Rect& box, cv::Point at, int stepPx) {
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
            const cv::Point p = at + cv::Point(dx * stepPx, dy * stepPx);
            if ((dx || dy) && box.contains(p) && unchanged.at<std::uint8_t>(p - box.tl())) return true;
        }
    return false;
}

}  // namespace

cv::Mat seenThroughPixels(const cv::Mat& object, const std::vector<TextureTrack>& tracks, int stepPx,
                          bool unchangedToo) {
    CV_Assert(object.type() == CV_8UC1 && stepPx > 0);
    cv::Mat seen(object.size(), CV_8U, cv::Scalar(0));
    // Over the object's box: each sample on the object says seen through, glimpsed through or
    // neither, and every pixel of the object takes its nearest sample's word.
    const cv::Rect box = cv::boundingRect(object);
    cv::Mat word(box.size(), CV_64F, cv::Scalar(std::numeric_limits<double>::quiet_NaN()));
    cv::Mat unchanged(box.size(), CV_8U, cv::Scalar(0));
    for (const TextureTrack& t : tracks) {
        if (t.onObject && t.state == TextureTrack::State::Unchanged && box.contains(t.pixel)) {
            unchanged.at<std::uint8_t>(t.pixel - box.tl()) = 255;
        }
    }
    bool any = false;
    for (const TextureTrack& t : tracks) {
        if (!t.onObject || !box.contains(t.pixel) || !object.at<std::uint8_t>(t.pixel)) continue;
        // A glimpse says so only inside the ice: beside clean surface its patch is more likely
        // part clean and part under an edge of opaque ice (which also leaves it unmeasured, its
        // look changed) than under a layer that lets it show.
        const bool glimpsedInside = t.glimpsed && !besideUnchanged(unchanged, box, t.pixel, stepPx);
        const bool through = t.state == TextureTrack::State::Changed ||
                             (unchangedToo && (t.state == TextureTrack::State::Unchanged || glimpsedInside));
        const bool glimpsedThrough = !through && glimpsedInside && t.glimpsedLookChanged;
        word.at<double>(t.pixel - box.tl()) = through ? kSeenThrough : glimpsedThrough ? kGlimpsedThrough : 0.0;
        any = any || through || glimpsedThrough;
    }
    if (!any) return seen;
    const cv::Mat inside = object(box);
    fillFromNearest(word, inside);
    cv::Mat part = seen(box);
    part.setTo(kGlimpsedThrough, (word == kGlimpsedThrough) & inside);
    part.setTo(kSeenThrough, (word == kSeenThrough) & inside);
    return seen;
}

SeenThroughIce seenThroughIce(const ThicknessMap& map) {
    SeenThroughIce seen;
    if (map.seenThrough.empty()) return seen;
    double sum = 0, glimpsedSum = 0;
    for (int j = 0; j < map.grid.nv; ++j)
        for (int i = 0; i < map.grid.nu; ++i) {
            const std::uint8_t word = map.seenThrough.at<std::uint8_t>(j, i);
            if (!word) continue;
            const double t = map.thickness.at<double>(j, i);
            if (std::isnan(t)) continue;
            // Signed: the noise of clean nodes cancels.
            if (word == kSeenThrough) {
                sum += t;
                ++seen.nodes;
            } else {
                glimpsedSum += t;
                ++seen.glimpsedNodes;
            }
        }
    seen.readMm3 = std::max(0.0, sum * map.grid.areaPerNodeMm2());
    seen.glimpsedReadMm3 = std::max(0.0, glimpsedSum * map.grid.areaPerNodeMm2());
    return seen;
}

double seenThroughShareMm3(const SeenThroughIce& seen) { return 0.5 * (kSeenThroughFactor - 1.0) * seen.readMm3; }

double seenThroughSigmaMm3(const SeenThroughIce& seen) {
    return 0.5 * (kSeenThroughFactor - 1.0) * (seen.readMm3 + seen.glimpsedReadMm3);
}

}  // namespace icewatch::volume
