// Image health for the quality gate: a wrong number is worse than none, so a dark, saturated,
// blurred or textureless capture is refused before it is measured. The blur before the gradient
// keeps sensor noise from passing for texture.
#include "core/volume/image_quality.hpp"

#include "core/health/image_health.hpp"

#include <cmath>
#include <sstream>

#include <opencv2/imgproc.hpp>

namespace icewatch::volume {

namespace {

// Texture is judged at the scale of the 2560x720 mode's eye, where the gate's floor was set: a
// finer mode sees the same texture over more pixels, its gradients per pixel smaller by the
// ratio. A blade rendered at 3840x1080 read 0.94, under the floor, and was refused as without
// texture where the same scene at 2560x720 passed. Reduced by area, the finer image also
// averages its sensor noise down, so noise does not pass for texture either.
constexpr int kReferenceEyeWidth = 1280;

// Mean gradient magnitude inside the mask, grey levels per pixel of the reference eye.
double meanGradient(const cv::Mat& grey, const cv::Mat& mask) {
    cv::Mat image = grey, inside = mask;
    if (grey.cols > kReferenceEyeWidth) {
        const double scale = static_cast<double>(kReferenceEyeWidth) / grey.cols;
        cv::resize(grey, image, {}, scale, scale, cv::INTER_AREA);
        cv::resize(mask, inside, image.size(), 0, 0, cv::INTER_NEAREST);
    }
    cv::Mat smooth, gx, gy, magnitude;
    cv::GaussianBlur(image, smooth, cv::Size(0, 0), 1.5);
    cv::Sobel(smooth, gx, CV_32F, 1, 0, 3, 1.0 / 8.0);
    cv::Sobel(smooth, gy, CV_32F, 0, 1, 3, 1.0 / 8.0);
    cv::magnitude(gx, gy, magnitude);
    return cv::mean(magnitude, inside)[0];
}

}  // namespace

ImageQuality measureImageQuality(const cv::Mat& grey, const cv::Mat& roi) {
    CV_Assert(grey.type() == CV_8U && (roi.empty() || (roi.type() == CV_8U && roi.size() == grey.size())));
    ImageQuality q;
    cv::Mat mask = roi.empty() ? cv::Mat(grey.size(), CV_8U, cv::Scalar(255)) : roi;
    const double count = cv::countNonZero(mask);
    if (count == 0) return q;
    q.meanGrey = cv::mean(grey, mask)[0];
    cv::Mat saturated = (grey >= 250) & mask;
    q.saturatedPercent = 100.0 * cv::countNonZero(saturated) / count;
    q.contrast = meanGradient(grey, mask) * health::exposureScale(q.meanGrey);
    return q;
}

std::optional<std::string> imageProblem(const ImageQuality& q, const Parameters& p, const std::string& which) {
    std::ostringstream reason;
    reason.precision(3);
    if (q.meanGrey < p.minMeanGrey) {
        reason << which << " image too dark: mean grey " << q.meanGrey << " < " << p.minMeanGrey;
    } else if (q.saturatedPercent > p.maxSaturatedPercent) {
        reason << which << " image saturated: " << q.saturatedPercent << " % of the region at 250 or more";
    } else if (q.contrast < p.minContrast) {
        reason << which << " image blurred or without texture: contrast " << q.contrast << " < " << p.minContrast;
    } else {
        return std::nullopt;
    }
    return reason.str();
}

std::optional<std::string> newSaturationProblem(const ImageQuality& baseline, const ImageQuality& current,
                                                const Parameters& p) {
    const double added = current.saturatedPercent - baseline.saturatedPercent;
    if (added <= p.maxNewSaturatedPercent) return std::nullopt;
    std::ostringstream reason;
    reason.precision(3);
    reason << "current image saturated over " << current.saturatedPercent << " % of the region, " << added
           << " % more than the baseline (max " << p.maxNewSaturatedPercent
           << " %): ice or the light on it clipped white there, its surface cannot be measured (a shorter "
              "exposure, or a duller light, keeps it)";
    return reason.str();
}

}  // namespace icewatch::volume
