#include "core/volume/image_quality.hpp"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

namespace icewatch::volume {
namespace {

cv::Mat texture(double gain) {
    cv::Mat noise(120, 160, CV_32F);
    cv::RNG(3).fill(noise, cv::RNG::NORMAL, 0.0, 6.0);
    cv::Mat grey;
    cv::Mat(noise + 110.0).convertTo(grey, CV_8U, gain);
    return grey;
}

// Less light scales every grey difference alike: a dim capture has the texture a bright one had.
TEST(ImageQuality, ContrastIsReadAtTheReferenceExposure) {
    const ImageQuality bright = measureImageQuality(texture(1.0), {});
    const ImageQuality dim = measureImageQuality(texture(0.4), {});
    EXPECT_NEAR(dim.meanGrey, 0.4 * bright.meanGrey, 1.0);
    EXPECT_NEAR(dim.contrast, bright.contrast, 0.08 * bright.contrast);
    // Above the reference level the figure is the image's own.
    const ImageQuality lit = measureImageQuality(texture(1.6), {});
    EXPECT_NEAR(lit.contrast, 1.6 * 110.0 / 128.0 * bright.contrast, 0.08 * lit.contrast);
}

// The same texture seen by a finer mode (3840x1080's eye is 1.5 times 2560x720's) spreads over
// more pixels: read per pixel of the finer image it would look weaker by that ratio, and a blade
// measured at 2560x720 was refused as without texture at 3840x1080.
TEST(ImageQuality, TheSameTextureInAFinerModeReadsTheSame) {
    cv::Mat noise(360, 640, CV_32F);
    cv::RNG(5).fill(noise, cv::RNG::NORMAL, 0.0, 8.0);
    cv::GaussianBlur(noise, noise, cv::Size(0, 0), 2.0);  // features of a few pixels, as a blade's
    cv::Mat coarse;
    cv::Mat(noise + 120.0).convertTo(coarse, CV_8U);
    cv::Mat reference, finer;
    cv::resize(coarse, reference, {1280, 720}, 0, 0, cv::INTER_CUBIC);  // the 2560x720 mode's eye
    cv::resize(coarse, finer, {1920, 1080}, 0, 0, cv::INTER_CUBIC);     // the 3840x1080 mode's eye
    const ImageQuality atReference = measureImageQuality(reference, {});
    const ImageQuality atFiner = measureImageQuality(finer, {});
    EXPECT_NEAR(atFiner.contrast, atReference.contrast, 0.05 * atReference.contrast)
        << "reference " << atReference.contrast << ", finer " << atFiner.contrast;
}

TEST(ImageQuality, ATexturelessCaptureIsRefusedHoweverBright) {
    Parameters p;
    const ImageQuality flat = measureImageQuality(cv::Mat(120, 160, CV_8U, cv::Scalar(60)), {});
    const auto problem = imageProblem(flat, p, "current");
    ASSERT_TRUE(problem.has_value());
    EXPECT_NE(problem->find("current image blurred or without texture"), std::string::npos) << *problem;
}

// White ice clipped under a brighter light leaves no texture to match: refused when it covers more
// of the region than the baseline's own clipping did, whatever the whole region's share.
TEST(ImageQuality, ClippingTheBaselineDidNotHaveIsRefused) {
    const Parameters p;
    cv::Mat clean = texture(1.0), iced = clean.clone();
    iced.rowRange(0, 12).setTo(255);  // 10 % of the region, under maxSaturatedPercent
    const ImageQuality before = measureImageQuality(clean, {}), after = measureImageQuality(iced, {});
    EXPECT_FALSE(imageProblem(after, p, "current").has_value());
    const auto problem = newSaturationProblem(before, after, p);
    ASSERT_TRUE(problem.has_value());
    EXPECT_NE(problem->find("current image saturated over 10 % of the region"), std::string::npos) << *problem;
    // Clipped alike in both captures (a lamp in the view) is the baseline's, not the ice's.
    EXPECT_FALSE(newSaturationProblem(after, after, p).has_value());
    cv::Mat glint = clean.clone();
    glint.rowRange(0, 3).setTo(255);  // 2.5 %: highlights
    EXPECT_FALSE(newSaturationProblem(before, measureImageQuality(glint, {}), p).has_value());
}

}  // namespace
}  // namespace icewatch::volume
