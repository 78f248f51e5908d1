// The pictures of one measurement, as `icewatch volume --debug-dir` writes them and the daemon
// serves them (GET /v1/images/latest/*.png). Their scales are fixed (the disparity band, and
// 0 .. pictures.max_thickness_mm), never stretched to the image's own range, so that the same
// colour means the same value on every day's picture.
#include "core/pictures/measurement_pictures.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/imgproc.hpp>

#include "core/common/error.hpp"
#include "core/pictures/annotation.hpp"
#include "core/pictures/colour_scale.hpp"

namespace icewatch::pictures {

namespace {

cv::Mat greyToColour(const cv::Mat& grey) {
    cv::Mat colour;
    cv::cvtColor(grey, colour, cv::COLOR_GRAY2BGR);
    return colour;
}

ColourScale thicknessScale(double maxThicknessMm) { return {0.0, maxThicknessMm, "mm", "thickness"}; }

ColourScale disparityScale(int minDisparity, int maxDisparity) {
    return {static_cast<double>(minDisparity), static_cast<double>(std::max(maxDisparity, minDisparity + 1)), "px",
            "disparity"};
}

// The pictures without their colour bars, so that a banner covers the picture and not the bar.
cv::Mat disparityImage(const cv::Mat& disparity, const ColourScale& scale, const cv::Mat& region) {
    if (disparity.type() != CV_32FC1) throw InvalidInput("disparity picture: disparity must be 32-bit float");
    cv::Mat values = disparity.clone();
    values.setTo(std::numeric_limits<float>::quiet_NaN(), disparity < 0);
    cv::Mat picture = falseColour(values, scale);
    drawOutline(picture, region);
    return picture;
}

cv::Mat thicknessImage(const cv::Mat& leftGrey, const cv::Mat& thicknessMm, const cv::Mat& region,
                       const ColourScale& scale) {
    if (leftGrey.type() != CV_8UC1) throw InvalidInput("thickness picture: the left eye must be 8-bit grey");
    cv::Mat picture = greyToColour(leftGrey);
    if (!thicknessMm.empty()) {
        if (thicknessMm.size() != leftGrey.size() || thicknessMm.type() != CV_32FC1) {
            throw InvalidInput("thickness picture: the thickness must be 32-bit float over the left eye");
        }
        const double shown = kShownThicknessFraction * scale.hi;
        for (int y = 0; y < picture.rows; ++y) {
            const auto* t = thicknessMm.ptr<float>(y);
            auto* out = picture.ptr<cv::Vec3b>(y);
            for (int x = 0; x < picture.cols; ++x) {
                if (std::isfinite(t[x]) && t[x] >= shown) out[x] = colourOf(t[x], scale);
            }
        }
    }
    drawOutline(picture, region);
    return picture;
}

}  // namespace

cv::Mat disparityPicture(const cv::Mat& disparity, int minDisparity, int maxDisparity, const cv::Mat& region) {
    const ColourScale scale = disparityScale(minDisparity, maxDisparity);
    return withColourBar(disparityImage(disparity, scale, region), scale);
}

cv::Mat thicknessPicture(const cv::Mat& leftGrey, const cv::Mat& thicknessMm, const cv::Mat& region,
                         double maxThicknessMm) {
    const ColourScale scale = thicknessScale(maxThicknessMm);
    return withColourBar(thicknessImage(leftGrey, thicknessMm, region, scale), scale);
}

MeasurementPictures drawMeasurement(const volume::Surface& current, const volume::VolumeResult& result,
                                    int maxDisparity, const PictureScale& scale) {
    MeasurementPictures pictures;
    if (current.rectifiedLeft.empty()) return pictures;
    pictures.left = greyToColour(current.rectifiedLeft);
    drawOutline(pictures.left, current.roi);
    const ColourScale band = disparityScale(0, maxDisparity);
    if (!current.disparity.empty()) pictures.disparity = disparityImage(current.disparity, band, current.roi);
    const ColourScale thickness = thicknessScale(scale.maxThicknessMm);
    pictures.thickness = thicknessImage(current.rectifiedLeft, result.ok ? result.thicknessImageMm : cv::Mat(),
                                        current.roi, thickness);
    if (!result.ok) {
        const std::string reason = "refused: " + result.reason;
        for (cv::Mat* picture : {&pictures.left, &pictures.disparity}) {
            if (!picture->empty()) writeBanner(*picture, reason);
        }
        writeBanner(pictures.thickness, reason + " (no thickness measured)");
    }
    if (!pictures.disparity.empty()) pictures.disparity = withColourBar(pictures.disparity, band);
    pictures.thickness = withColourBar(pictures.thickness, thickness);
    return pictures;
}

}  // namespace icewatch::pictures
