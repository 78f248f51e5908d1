// Ice through which the object's own texture was seen (seen_through.hpp).
#include "core/volume/seen_through.hpp"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "core/volume/thickness_map.hpp"

namespace icewatch::volume {

cv::Mat seenThroughPixels(const cv::Mat& object, const std::vector<TextureTrack>& tracks) {
    CV_Assert(object.type() == CV_8UC1);
    cv::Mat seen(object.size(), CV_8U, cv::Scalar(0));
    // The object's samples as seeds of a nearest-sample partition over the object's box
    // (distanceTransform labels every zero pixel on its own; each seed is one pixel).
    const cv::Rect box = cv::boundingRect(object);
    std::vector<std::size_t> onObject;
    bool any = false;
    for (std::size_t i = 0; i < tracks.size(); ++i) {
        const TextureTrack& t = tracks[i];
        if (!t.onObject || !box.contains(t.pixel) || !object.at<std::uint8_t>(t.pixel)) continue;
        onObject.push_back(i);
        any = any || t.state == TextureTrack::State::Changed;
    }
    if (!any) return seen;
    cv::Mat seeds(box.size(), CV_8U, cv::Scalar(255));
    for (std::size_t i : onObject) seeds.at<std::uint8_t>(tracks[i].pixel - box.tl()) = 0;
    cv::Mat distance, labels;
    cv::distanceTransform(seeds, distance, labels, cv::DIST_L2, cv::DIST_MASK_5, cv::DIST_LABEL_PIXEL);
    std::vector<std::uint8_t> labelSeen(onObject.size() + 1, 0);
    for (std::size_t i : onObject) {
        const auto label = static_cast<std::size_t>(labels.at<int>(tracks[i].pixel - box.tl()));
        const bool through = tracks[i].state == TextureTrack::State::Changed;
        if (label < labelSeen.size()) labelSeen[label] = through ? 255 : 0;
    }
    for (int y = 0; y < box.height; ++y) {
        const auto* inside = object.ptr<std::uint8_t>(box.y + y) + box.x;
        const int* label = labels.ptr<int>(y);
        auto* out = seen.ptr<std::uint8_t>(box.y + y) + box.x;
        for (int x = 0; x < box.width; ++x) {
            const auto l = static_cast<std::size_t>(label[x]);
            if (inside[x] && l < labelSeen.size()) out[x] = labelSeen[l];
        }
    }
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

double seenThroughSigmaMm3(const SeenThroughIce& seen) { return seenThroughShareMm3(seen) / std::sqrt(3.0); }

}  // namespace icewatch::volume
