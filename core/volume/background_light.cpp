// The scene's change of light from its background (background_light.hpp).
#include "core/volume/background_light.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <opencv2/imgproc.hpp>

#include "core/volume/robust_statistics.hpp"

namespace icewatch::volume {

std::optional<double> backgroundLightRatio(const cv::Mat& baselineGrey, const cv::Mat& currentGrey, const cv::Mat& roi,
                                           const cv::Rect& baselineWindow, const cv::Rect& currentWindow,
                                           const BackgroundLightOptions& o) {
    CV_Assert(baselineGrey.type() == CV_32FC1 && currentGrey.type() == CV_32FC1 && roi.type() == CV_8UC1 &&
              baselineGrey.size() == currentGrey.size() && roi.size() == baselineGrey.size());
    const cv::Rect both = baselineWindow & currentWindow & cv::Rect(0, 0, roi.cols, roi.rows);
    if (both.empty()) return std::nullopt;
    cv::Mat object;
    const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * o.marginPx + 1, 2 * o.marginPx + 1});
    cv::dilate(roi(both), object, kernel);
    double baselineSum = 0, currentSum = 0;
    int pixels = 0;
    for (int y = 0; y < both.height; ++y) {
        const float* b = baselineGrey.ptr<float>(both.y + y) + both.x;
        const float* c = currentGrey.ptr<float>(both.y + y) + both.x;
        const std::uint8_t* inObject = object.ptr<std::uint8_t>(y);
        for (int x = 0; x < both.width; ++x) {
            if (inObject[x] || b[x] < o.lowestGrey || b[x] > o.highestGrey || c[x] < o.lowestGrey ||
                c[x] > o.highestGrey) {
                continue;
            }
            baselineSum += b[x];
            currentSum += c[x];
            ++pixels;
        }
    }
    if (pixels < o.minPixels || baselineSum <= 0) return std::nullopt;
    return currentSum / baselineSum;
}

std::string objectLightNote(const std::vector<TextureTrack>& tracks, std::optional<double> lightRatio,
                            double maxChange) {
    if (!lightRatio) return {};
    std::vector<double> ratios;
    for (const TextureTrack& t : tracks)
        if (t.onObject && t.state != TextureTrack::State::Untracked) ratios.push_back(t.brightnessRatio);
    if (ratios.empty()) return {};
    const double objectRatio = median(std::move(ratios));
    if (std::abs(objectRatio / *lightRatio - 1.0) <= maxChange) return {};
    std::ostringstream note;
    note.precision(3);
    note << "the object's texture changed its brightness by " << 100.0 * (objectRatio - 1.0) << " %, its background by "
         << 100.0 * (*lightRatio - 1.0) << " %: a layer of ice over all of it, or light on the object alone";
    return note.str();
}

}  // namespace icewatch::volume
