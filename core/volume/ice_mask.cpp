// Where the ice may be, from the texture that vouches for clean surface (ice_mask.hpp).
#include "core/volume/ice_mask.hpp"

#include <opencv2/imgproc.hpp>

namespace icewatch::volume {

namespace {

// Per track: the sample vouches for clean surface. A sample that did not vouch, whose look did
// not change, with fewer than two of its eight neighbours on the sample lattice that did not
// vouch either, is the trackers' noise (a patch too weak to be precise, a pair outside 2.5 σ by
// chance), not ice: ice covers more than one patch, or changes the look of the one it covers.
std::vector<std::uint8_t> vouchingSamples(const cv::Size& size, const std::vector<TextureTrack>& tracks,
                                          const std::vector<std::uint8_t>& clean, int stepPx) {
    std::vector<std::uint8_t> vouches(clean.begin(), clean.end());
    const int cols = size.width / stepPx + 2, rows = size.height / stepPx + 2;
    cv::Mat lattice(rows, cols, CV_8UC1, cv::Scalar(0));  // 1 vouched, 2 did not
    auto cellOf = [&](cv::Point p) { return cv::Point(p.x / stepPx, p.y / stepPx); };
    for (std::size_t i = 0; i < tracks.size(); ++i) {
        if (tracks[i].onObject) lattice.at<std::uint8_t>(cellOf(tracks[i].pixel)) = clean[i] ? 1 : 2;
    }
    for (std::size_t i = 0; i < tracks.size(); ++i) {
        if (!tracks[i].onObject || clean[i] || tracks[i].state == TextureTrack::State::Changed) continue;
        const cv::Point c = cellOf(tracks[i].pixel);
        int others = 0;
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const cv::Point n = c + cv::Point(dx, dy);
                const bool inside = n.x >= 0 && n.y >= 0 && n.x < cols && n.y < rows;
                if ((dx || dy) && inside && lattice.at<std::uint8_t>(n) == 2) ++others;
            }
        if (others < 2) vouches[i] = 1;
    }
    return vouches;
}

}  // namespace

cv::Mat iceMask(const cv::Mat& object, const std::vector<TextureTrack>& tracks, const std::vector<std::uint8_t>& clean,
                int stepPx, int growPx) {
    CV_Assert(object.type() == CV_8UC1 && tracks.size() == clean.size());
    const std::vector<std::uint8_t> vouches = vouchingSamples(object.size(), tracks, clean, stepPx);
    // Each sample's cell (the stepPx square around it), 0 in the map of its kind, over the object's
    // box and the cells' reach beyond it alone: every cell lies there, and the distances below are
    // Euclidean, so the rest of the frame changes none of them.
    const cv::Rect frame({0, 0}, object.size());
    const int half = stepPx / 2;
    const cv::Rect box = cv::boundingRect(object);
    const cv::Rect cells = (box + cv::Size(2 * stepPx, 2 * stepPx) - cv::Point(stepPx, stepPx)) & frame;
    cv::Mat mask = object.clone();
    if (!cells.empty()) {
        cv::Mat notClean(cells.size(), CV_8UC1, cv::Scalar(255)), notOther(cells.size(), CV_8UC1, cv::Scalar(255));
        for (std::size_t i = 0; i < tracks.size(); ++i) {
            if (!tracks[i].onObject) continue;
            const cv::Rect cell = cv::Rect(tracks[i].pixel.x - half, tracks[i].pixel.y - half, stepPx, stepPx) & cells;
            (vouches[i] ? notClean : notOther)(cell - cells.tl()).setTo(0);
        }
        // What no cell covers (the rim the patches cannot reach, a hole in the baseline's
        // disparities) takes the word of the nearest cell: beside clean texture it is as clean,
        // beside what did not vouch as possibly iced.
        cv::Mat toClean, toOther;
        cv::distanceTransform(notClean, toClean, cv::DIST_L2, cv::DIST_MASK_PRECISE);
        cv::distanceTransform(notOther, toOther, cv::DIST_L2, cv::DIST_MASK_PRECISE);
        for (int y = 0; y < cells.height; ++y) {
            std::uint8_t* m = mask.ptr<std::uint8_t>(cells.y + y) + cells.x;
            const std::uint8_t* inClean = notClean.ptr<std::uint8_t>(y);
            const std::uint8_t* inOther = notOther.ptr<std::uint8_t>(y);
            const float* dc = toClean.ptr<float>(y);
            const float* dn = toOther.ptr<float>(y);
            for (int x = 0; x < cells.width; ++x) {
                const bool vouched = !inClean[x] || (inOther[x] && dc[x] < dn[x]);
                if (vouched) m[x] = 0;
            }
        }
    }
    if (growPx > 0) {
        // Only the object's box and the reach of the growth around it: nothing outside it is set,
        // and the frame's zeros beyond it are the dilation's own border (a tenth of the time of
        // dilating the frame with a disc this large).
        const cv::Rect reach = (box + cv::Size(2 * growPx, 2 * growPx) - cv::Point(growPx, growPx)) & frame;
        if (!reach.empty()) {
            cv::Mat part = mask(reach);
            cv::dilate(part, part, cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * growPx + 1, 2 * growPx + 1}));
        }
    }
    return mask & object;
}

}  // namespace icewatch::volume
