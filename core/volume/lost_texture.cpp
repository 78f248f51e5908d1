// Texture the trackers lost, and whether stereo reads what hid it (lost_texture.hpp).
#include "core/volume/lost_texture.hpp"

#include <cmath>

namespace icewatch::volume {

cv::Mat unreadLostTexture(const std::vector<TextureTrack>& tracks, const RectifiedCapture& current,
                          const std::function<cv::Point2d(cv::Point2d)>& toCurrent, const TextureTrackOptions& options) {
    CV_Assert(current.disparity.type() == CV_32FC1);
    const cv::Rect frame({}, current.disparity.size());
    cv::Mat unread(frame.size(), CV_8U, cv::Scalar(0));
    const int step = options.stepPx;
    for (const TextureTrack& t : tracks) {
        if (!t.onObject || !t.inBaseline || t.state != TextureTrack::State::Untracked || t.glimpsed) continue;
        const cv::Point2d at = toCurrent(cv::Point2d(t.pixel));
        // The range first (NaN fails it too): a huge place must not reach the rounding.
        if (!(at.x > -0.5 && at.y > -0.5 && at.x < frame.width - 0.5 && at.y < frame.height - 0.5)) continue;
        const cv::Point place(static_cast<int>(std::lround(at.x)), static_cast<int>(std::lround(at.y)));
        const PatchTrack inCurrent = stereoPatchTrack(current, place, options);
        const bool read = inCurrent.found && std::sqrt(inCurrent.covariance(0, 0)) <= options.maxShiftSigmaPx;
        if (!read) unread(cv::Rect(place.x - step / 2, place.y - step / 2, step, step) & frame).setTo(255);
    }
    return unread;
}

}  // namespace icewatch::volume
