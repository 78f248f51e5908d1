// Where the ice may be, from the texture that vouches for clean surface (ice_mask.hpp).
#include "core/volume/ice_mask.hpp"

#include <opencv2/imgproc.hpp>

namespace icewatch::volume {

cv::Mat iceMask(const cv::Mat& object, const std::vector<TextureTrack>& tracks, const std::vector<std::uint8_t>& clean,
                int stepPx, int growPx) {
    CV_Assert(object.type() == CV_8UC1 && tracks.size() == clean.size());
    cv::Mat mask = object.clone();
    const int half = stepPx / 2;
    for (std::size_t i = 0; i < tracks.size(); ++i) {
        if (!tracks[i].onObject || !clean[i]) continue;
        const cv::Point& p = tracks[i].pixel;
        cv::rectangle(mask, {p.x - half, p.y - half}, {p.x - half + stepPx - 1, p.y - half + stepPx - 1}, cv::Scalar(0),
                      cv::FILLED);
    }
    if (growPx > 0) {
        // Only the object's box and the reach of the growth around it: nothing outside it is set,
        // and the frame's zeros beyond it are the dilation's own border (a tenth of the time of
        // dilating the frame with a disc this large).
        const cv::Rect box = cv::boundingRect(object);
        const cv::Rect reach = (box + cv::Size(2 * growPx, 2 * growPx) - cv::Point(growPx, growPx)) &
                               cv::Rect({0, 0}, object.size());
        if (!reach.empty()) {
            cv::Mat part = mask(reach);
            cv::dilate(part, part, cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * growPx + 1, 2 * growPx + 1}));
        }
    }
    return mask & object;
}

}  // namespace icewatch::volume
