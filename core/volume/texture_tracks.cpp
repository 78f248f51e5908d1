// The baseline's texture followed into the current capture in both eyes (texture_tracks.hpp).
#include "core/volume/texture_tracks.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/imgproc.hpp>

#include "core/common/fixed_bands.hpp"
#include "core/volume/image_motion.hpp"
#include "core/volume/robust_statistics.hpp"

namespace icewatch::volume {

namespace {

// Q·[x y d 1]ᵀ, dehomogenised; and its Jacobian with respect to (x, y, d).
cv::Vec3d lift(const cv::Matx44d& q, double x, double y, double d, cv::Matx33d* jacobian = nullptr) {
    const cv::Vec4d h = q * cv::Vec4d(x, y, d, 1.0);
    const cv::Vec3d p(h[0] / h[3], h[1] / h[3], h[2] / h[3]);
    if (jacobian) {
        for (int k = 0; k < 3; ++k) {
            const double dw = q(3, k);
            for (int i = 0; i < 3; ++i) (*jacobian)(i, k) = (q(i, k) - p[i] * dw) / h[3];
        }
    }
    return p;
}

double worstSigma(const cv::Matx22d& covariance) {
    const double a = covariance(0, 0), b = covariance(0, 1), c = covariance(1, 1);
    const double mean = 0.5 * (a + c), spread = std::sqrt(0.25 * (a - c) * (a - c) + b * b);
    return std::sqrt(std::max(0.0, mean + spread));
}

// The look of a patch changed in a way light does not change it: its texture is gone, or a
// layer added brightness that does not scale with what is under it.
bool appearanceChanged(const PatchTrack& t, const TextureTrackOptions& o) {
    if (t.zncc < o.minZncc) return true;
    return std::abs(t.offset) > std::max(o.offsetSigmas * t.offsetSigma, o.minOffsetShare * t.meanFrom);
}

// fn(i) for i in [0, n), in fixed bands.
template <class F>
void forEachIndex(std::size_t n, const F& fn) {
    forEachFixedBand(n, [&](int, std::size_t begin, std::size_t end) {
        for (std::size_t i = begin; i < end; ++i) fn(i);
    });
}

// The baseline's disparity at a sample, re-measured by its stereo patch track (NaN: not found).
double stereoDisparity(const RectifiedCapture& baseline, cv::Point at, const TextureTrackOptions& o) {
    const PatchTrack inBaseline = stereoPatchTrack(baseline, at, o);
    return inBaseline.found ? -inBaseline.shift.x : std::numeric_limits<double>::quiet_NaN();
}

TextureTrack trackOne(const RectifiedCapture& baseline, const RectifiedCapture& current, cv::Point at, bool onObject,
                      double disparity, const cv::Matx44d& q, cv::Point2d prior, const TextureTrackOptions& o) {
    TextureTrack out;
    out.pixel = at;
    out.onObject = onObject;
    if (std::isnan(disparity)) return out;
    out.inBaseline = true;
    PatchTrackOptions temporal = o.patch;
    temporal.searchPx = o.temporalSearchPx;
    const PatchTrack left = trackPatch(baseline.left, current.left, at, prior, temporal);
    if (!left.found) return out;
    out.zncc = left.zncc;
    out.offsetGrey = left.offset;
    out.brightnessRatio = left.brightnessRatio;
    // The right patch at the nearest whole pixel: the image motion of a rigid scene changes by
    // thousandths of a pixel over the half pixel this moves it.
    const cv::Point atRight(static_cast<int>(std::lround(at.x - disparity)), at.y);
    PatchTrackOptions near = o.patch;
    near.searchPx = 2;
    const PatchTrack right = trackPatch(baseline.right, current.right, atRight, left.shift, near);
    if (!right.found) return out;
    const bool changed = appearanceChanged(left, o) || appearanceChanged(right, o);
    if (std::max(worstSigma(left.covariance), worstSigma(right.covariance)) > o.maxShiftSigmaPx) {
        // Found in both eyes where the motion puts it, but less precisely than evidence must be:
        // a glimpse of the texture (a chance peak of a hidden one lies anywhere in the search).
        out.glimpsed = left.zncc >= o.minZncc && right.zncc >= o.minZncc &&
                       cv::norm(left.shift - prior) <= o.glimpseReachPx;
        out.glimpsedLookChanged = out.glimpsed && changed;
        return out;
    }
    const double currentDisparity = disparity + left.shift.x - right.shift.x;
    if (!(currentDisparity > 0)) return out;
    cv::Matx33d jacobian;
    out.baselineDisparity = disparity;
    out.currentPixel = cv::Point2d(at) + left.shift;
    out.currentDisparity = currentDisparity;
    out.baselineMm = lift(q, at.x, at.y, disparity);
    out.currentMm = lift(q, at.x + left.shift.x, at.y + left.shift.y, currentDisparity, &jacobian);
    // (x, y, d) of the current point: x and y from the left track, d from both; the baseline's
    // own disparity error moves both points alike and cancels in their difference.
    const double floor = o.minShiftSigmaPx * o.minShiftSigmaPx;
    const cv::Matx22d l = left.covariance + cv::Matx22d(floor, 0, 0, floor);
    const double rx = right.covariance(0, 0) + floor;
    const cv::Matx33d input(l(0, 0), l(0, 1), l(0, 0),  //
                            l(1, 0), l(1, 1), l(1, 0),  //
                            l(0, 0), l(0, 1), l(0, 0) + rx);
    out.covarianceMm2 = jacobian * input * jacobian.t();
    out.state = changed ? TextureTrack::State::Changed : TextureTrack::State::Unchanged;
    return out;
}

}  // namespace

PatchTrack stereoPatchTrack(const RectifiedCapture& capture, cv::Point at, const TextureTrackOptions& o) {
    const float matched = capture.disparity.at<float>(at);
    if (!(matched > 0)) return {};
    PatchTrackOptions stereo = o.patch;
    stereo.horizontalOnly = true;
    stereo.searchPx = 2;
    return trackPatch(capture.left, capture.right, at, {-matched, 0.0}, stereo);
}

BaselineSamples baselineSamples(const RectifiedCapture& baseline, const cv::Mat& object, const TextureTrackOptions& o) {
    CV_Assert(object.type() == CV_8UC1 && baseline.disparity.size() == object.size());
    const int r = o.patch.radiusPx;
    const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * r + 1, 2 * r + 1});
    cv::Mat inside, outside;
    cv::erode(object, inside, kernel);
    cv::dilate(object, outside, kernel);
    BaselineSamples samples;
    // The pixels isSamplePixel names (the slanted windows refine them for these tracks).
    for (int y = o.stepPx / 2; y < object.rows; y += o.stepPx)
        for (int x = o.stepPx / 2; x < object.cols; x += o.stepPx) {
            const bool in = inside.at<std::uint8_t>(y, x) != 0;
            if (!in && outside.at<std::uint8_t>(y, x) != 0) continue;  // astride the outline
            if (!(baseline.disparity.at<float>(y, x) > 0)) continue;
            samples.pixels.emplace_back(x, y);
            samples.onObject.push_back(in ? 1 : 0);
        }
    samples.disparity.resize(samples.pixels.size());
    forEachIndex(samples.pixels.size(), [&](std::size_t i) {
        samples.disparity[i] = stereoDisparity(baseline, samples.pixels[i], o);
    });
    return samples;
}

std::vector<TextureTrack> trackTexture(const BaselineSamples& samples, const RectifiedCapture& baseline,
                                       const RectifiedCapture& current, const cv::Matx44d& q,
                                       const cv::Matx23d& imageMotion, std::optional<double> lightRatio,
                                       const TextureTrackOptions& o) {
    // A patch, searched around where the motion puts it, must lie inside the current window.
    const int reach = o.patch.radiusPx + o.temporalSearchPx + 1;
    const cv::Rect window = current.left.frameRect();
    const cv::Rect2d reachable(window.x + reach, window.y + reach, window.width - 2 * reach - 1,
                               window.height - 2 * reach - 1);
    std::vector<std::size_t> used;
    std::vector<cv::Point2d> priors;
    for (std::size_t i = 0; i < samples.pixels.size(); ++i) {
        const cv::Point2d at(samples.pixels[i]), prior = mapped(imageMotion, at) - at;
        if (!reachable.contains(at + prior) || !reachable.contains(at)) continue;
        used.push_back(i);
        priors.push_back(prior);
    }
    std::vector<TextureTrack> tracks(used.size());
    forEachIndex(used.size(), [&](std::size_t k) {
        const std::size_t i = used[k];
        tracks[k] = trackOne(baseline, current, samples.pixels[i], samples.onObject[i] != 0, samples.disparity[i], q,
                             priors[k], o);
    });
    // The scene's own change of brightness (light), and the patches that changed otherwise.
    double sceneRatio = 1.0;
    if (lightRatio) {
        sceneRatio = *lightRatio;
    } else {
        std::vector<double> ratios;
        for (const TextureTrack& t : tracks)
            if (t.state != TextureTrack::State::Untracked) ratios.push_back(t.brightnessRatio);
        if (!ratios.empty()) sceneRatio = median(std::move(ratios));
    }
    for (TextureTrack& t : tracks) {
        const bool brightnessChanged = std::abs(t.brightnessRatio / sceneRatio - 1.0) > o.maxBrightnessChange;
        if (t.state == TextureTrack::State::Unchanged && brightnessChanged) t.state = TextureTrack::State::Changed;
        if (t.glimpsed && brightnessChanged) t.glimpsedLookChanged = true;
    }
    return tracks;
}

}  // namespace icewatch::volume
