// Pictures for people: the colour bar says what the colours mean, the scale is the same for every
// input, the thickness lies over the grey eye, a refusal's reason is written on its pictures.
#include <cmath>
#include <limits>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "core/pictures/annotation.hpp"
#include "core/pictures/colour_scale.hpp"
#include "core/pictures/measurement_pictures.hpp"

namespace icewatch::pictures {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

cv::Mat greyEye() {
    cv::Mat grey(120, 160, CV_8U);
    for (int y = 0; y < grey.rows; ++y)
        for (int x = 0; x < grey.cols; ++x) grey.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>(60 + (x + y) % 90);
    return grey;
}

// A square of ice, `mm` thick, at the middle of the eye; no measurement elsewhere.
cv::Mat iceSquare(float mm) {
    cv::Mat thickness(120, 160, CV_32F, cv::Scalar(kNaN));
    thickness(cv::Rect(60, 40, 40, 40)).setTo(mm);
    return thickness;
}

cv::Mat regionMask() {
    cv::Mat region = cv::Mat::zeros(120, 160, CV_8U);
    region(cv::Rect(20, 20, 120, 80)).setTo(255);
    return region;
}

TEST(Pictures, TheColourBarShowsTheScaleFromBottomToTop) {
    const cv::Mat picture = thicknessPicture(greyEye(), iceSquare(3.0f), regionMask(), 10.0);
    const cv::Rect bar = colourBarRect({160, 120});
    ASSERT_GE(picture.cols, bar.x + bar.width);
    ASSERT_GE(picture.rows, bar.y + bar.height);
    ASSERT_GT(bar.height, 20);
    const ColourScale scale{0.0, 10.0, "mm", "thickness"};
    const int x = bar.x + bar.width / 2;
    EXPECT_EQ(picture.at<cv::Vec3b>(bar.y, x), colourOf(10.0, scale));
    EXPECT_EQ(picture.at<cv::Vec3b>(bar.y + bar.height - 1, x), colourOf(0.0, scale));
    // Row r shows hi - (hi - lo)·r / (height - 1).
    const int r = (bar.height - 1) / 4;
    EXPECT_EQ(picture.at<cv::Vec3b>(bar.y + r, x), colourOf(10.0 - 10.0 * r / (bar.height - 1), scale));
    // The bottom and top differ: a bar, not a block.
    EXPECT_NE(colourOf(0.0, scale), colourOf(10.0, scale));
    // The strip beside the picture carries the labels: some white text in it.
    const cv::Mat strip = picture(cv::Rect(160, 0, picture.cols - 160, picture.rows));
    cv::Mat white;
    cv::inRange(strip, cv::Scalar(200, 200, 200), cv::Scalar(255, 255, 255), white);
    EXPECT_GT(cv::countNonZero(white), 20);
}

TEST(Pictures, TheThicknessScaleIsTheSameForEveryInput) {
    // Two days: thin ice and thick ice. The old pictures stretched each to its own maximum, so
    // both squares came out the same colour; on a fixed scale they differ, and each is its value's.
    const ColourScale scale{0.0, 10.0, "mm", "thickness"};
    const cv::Mat thin = thicknessPicture(greyEye(), iceSquare(2.0f), regionMask(), 10.0);
    const cv::Mat thick = thicknessPicture(greyEye(), iceSquare(8.0f), regionMask(), 10.0);
    EXPECT_EQ(thin.at<cv::Vec3b>(60, 80), colourOf(2.0, scale));
    EXPECT_EQ(thick.at<cv::Vec3b>(60, 80), colourOf(8.0, scale));
    EXPECT_NE(thin.at<cv::Vec3b>(60, 80), thick.at<cv::Vec3b>(60, 80));
    const cv::Rect bar = colourBarRect({160, 120});
    EXPECT_EQ(cv::norm(thin(bar), thick(bar), cv::NORM_INF), 0.0) << "the same bar on both days";
}

TEST(Pictures, TheThicknessLiesOverTheGreyEyeInsideTheOutline) {
    const cv::Mat grey = greyEye();
    cv::Mat thickness = iceSquare(5.0f);
    thickness(cv::Rect(30, 30, 10, 10)).setTo(0.0f);  // measured clean: the blade shows through
    const cv::Mat picture = thicknessPicture(grey, thickness, regionMask(), 10.0);
    const std::uint8_t g = grey.at<std::uint8_t>(35, 35);
    EXPECT_EQ(picture.at<cv::Vec3b>(35, 35), cv::Vec3b(g, g, g));
    const std::uint8_t h = grey.at<std::uint8_t>(110, 150);
    EXPECT_EQ(picture.at<cv::Vec3b>(110, 150), cv::Vec3b(h, h, h)) << "outside the region: the eye as it is";
    EXPECT_EQ(picture.at<cv::Vec3b>(60, 80), colourOf(5.0, {0.0, 10.0, "mm", "thickness"}));
    // The outline: the region's border is drawn in a colour no grey has.
    const cv::Vec3b edge = picture.at<cv::Vec3b>(60, 20);
    EXPECT_FALSE(edge[0] == edge[1] && edge[1] == edge[2]) << "outline on the region's left edge";
}

TEST(Pictures, TheDisparityIsShownOnTheBandItWasMatchedIn) {
    cv::Mat disparity(120, 160, CV_32F, cv::Scalar(40.0f));
    disparity(cv::Rect(0, 0, 10, 120)).setTo(-1.0f);  // no match
    const cv::Mat picture = disparityPicture(disparity, 32, 64);
    const ColourScale band{32.0, 64.0, "px", "disparity"};
    EXPECT_EQ(picture.at<cv::Vec3b>(60, 80), colourOf(40.0, band));
    EXPECT_EQ(picture.at<cv::Vec3b>(60, 5), cv::Vec3b(0, 0, 0)) << "no disparity: black";
    const cv::Rect bar = colourBarRect({160, 120});
    EXPECT_EQ(picture.at<cv::Vec3b>(bar.y, bar.x + 1), colourOf(64.0, band));
}

TEST(Pictures, ARefusalKeepsTheLeftEyeAndTheDisparityWithItsReason) {
    volume::Surface current;
    current.rectifiedLeft = greyEye();
    current.disparity = cv::Mat(120, 160, CV_32F, cv::Scalar(20.0f));
    current.roi = regionMask();
    volume::VolumeResult refused;
    refused.ok = false;
    refused.reason = "too few valid disparities in the current region: 12 % < 50 %";
    const MeasurementPictures pictures = drawMeasurement(current, refused, 64, {});
    ASSERT_FALSE(pictures.left.empty());
    ASSERT_FALSE(pictures.disparity.empty());
    ASSERT_FALSE(pictures.thickness.empty());
    for (const cv::Mat* picture : {&pictures.left, &pictures.disparity, &pictures.thickness}) {
        // The reason's band across the top: dark, with white letters in it.
        const cv::Mat top = (*picture)(cv::Rect(0, 0, 160, 24));
        cv::Mat white;
        cv::inRange(top, cv::Scalar(200, 200, 200), cv::Scalar(255, 255, 255), white);
        EXPECT_GT(cv::countNonZero(white), 10);
    }
    // Below the band, the picture is still there.
    const std::uint8_t g = current.rectifiedLeft.at<std::uint8_t>(110, 150);
    EXPECT_EQ(pictures.left.at<cv::Vec3b>(110, 150), cv::Vec3b(g, g, g));
    EXPECT_EQ(pictures.disparity.at<cv::Vec3b>(110, 150), colourOf(20.0, {0.0, 64.0, "px", "disparity"}));

    volume::VolumeResult ok;
    ok.ok = true;
    ok.thicknessImageMm = iceSquare(4.0f);
    const MeasurementPictures measured = drawMeasurement(current, ok, 64, {});
    const std::uint8_t t = current.rectifiedLeft.at<std::uint8_t>(5, 5);
    EXPECT_EQ(measured.left.at<cv::Vec3b>(5, 5), cv::Vec3b(t, t, t)) << "no banner on a measurement";
    EXPECT_EQ(measured.thickness.at<cv::Vec3b>(60, 80), colourOf(4.0, {0.0, 10.0, "mm", "thickness"}));
}

TEST(Pictures, ALongReasonWrapsOntoMoreLines) {
    cv::Mat a(200, 160, CV_8UC3, cv::Scalar::all(128)), b = a.clone();
    const cv::Rect shortBand = writeBanner(a, "refused: dark");
    const cv::Rect longBand = writeBanner(b, "refused: the registration moved the object by 41.2 mm, more than "
                                             "max_registration_mm, which the camera or the blade did");
    EXPECT_GT(longBand.height, shortBand.height);
    EXPECT_EQ(longBand.width, 160);
}

TEST(Pictures, FalseColourLeavesNoValueBlack) {
    cv::Mat values(2, 2, CV_64F, cv::Scalar(1.0));
    values.at<double>(0, 1) = std::nan("");
    values.at<double>(1, 0) = std::numeric_limits<double>::infinity();
    const cv::Mat colour = falseColour(values, {0.0, 2.0, "", ""});
    EXPECT_EQ(colour.at<cv::Vec3b>(0, 1), cv::Vec3b(0, 0, 0));
    EXPECT_EQ(colour.at<cv::Vec3b>(1, 0), cv::Vec3b(0, 0, 0));
    EXPECT_EQ(colour.at<cv::Vec3b>(0, 0), colourOf(1.0, {0.0, 2.0, "", ""}));
}

}  // namespace
}  // namespace icewatch::pictures
