// Ice through which the object's own texture was seen (seen_through.hpp).
#include "core/volume/seen_through.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/imgproc.hpp>

#include "core/volume/height_grid.hpp"
#include "core/volume/thickness_map.hpp"

namespace icewatch::volume {

cv::Mat seenThroughPixels(const cv::Mat& object, const std::vector<TextureTrack>& tracks, bool unchangedToo) {
    CV_Assert(object.type() == CV_8UC1);
    cv::Mat seen(object.size(), CV_8U, cv::Scalar(0));
    // Over the object's box: each sample on the object says 1 (seen through) or 0, and every
    // pixel of the object takes its nearest sample's word.
    const cv::Rect box = cv::boundingRect(object);
    cv::Mat word(box.size(), CV_64F, cv::Scalar(std::numeric_limits<double>::quiet_NaN()));
    bool any = false;
    for (const TextureTrack& t : tracks) {
        if (!t.onObject || !box.contains(t.pixel) || !object.at<std::uint8_t>(t.pixel)) continue;
        const bool through = t.state == TextureTrack::State::Changed ||
                             (unchangedToo && t.state == TextureTrack::State::Unchanged);
        word.at<double>(t.pixel - box.tl()) = through ? 1.0 : 0.0;
        any = any || through;
    }
    if (!any) return seen;
    const cv::Mat inside = object(box);
    fillFromNearest(word, inside);
    cv::Mat part = seen(box);
    part.setTo(255, (word > 0.5) & inside);
    return seen;
}

SeenThroughIce seenThroughIce(const ThicknessMap& map) {
    SeenThroughIce seen;
    if (map.seenThrough.empty()) return seen;
    double sum = 0;
    for (int j = 0; j < map.grid.nv; ++j)
        for (int i = 0; i < map.grid.nu; ++i) {
            if (!map.seenThrough.at<std::uint8_t>(j, i)) continue;
            const double t = map.thickness.at<double>(j, i);
            if (std::isnan(t)) continue;
            sum += t;  // signed: the noise of clean nodes cancels
            ++seen.nodes;
        }
    seen.readMm3 = std::max(0.0, sum * map.grid.areaPerNodeMm2());
    return seen;
}

double seenThroughShareMm3(const SeenThroughIce& seen) { return 0.5 * (kSeenThroughFactor - 1.0) * seen.readMm3; }

double seenThroughSigmaMm3(const SeenThroughIce& seen) { return seenThroughShareMm3(seen); }

}  // namespace icewatch::volume
