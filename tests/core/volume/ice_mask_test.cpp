#include "core/volume/ice_mask.hpp"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

namespace icewatch::volume {
namespace {

// The mask by its definition, pixel by pixel: the object where no clean track's cell covers it,
// dilated over the whole frame by the disc, cut back to the object.
cv::Mat iceMaskOverTheFrame(const cv::Mat& object, const std::vector<TextureTrack>& tracks,
                            const std::vector<std::uint8_t>& clean, int stepPx, int growPx) {
    cv::Mat mask = object.clone();
    for (int y = 0; y < mask.rows; ++y)
        for (int x = 0; x < mask.cols; ++x)
            for (std::size_t i = 0; i < tracks.size(); ++i) {
                const cv::Point corner = tracks[i].pixel - cv::Point(stepPx / 2, stepPx / 2);
                const bool inCell = x >= corner.x && x < corner.x + stepPx && y >= corner.y && y < corner.y + stepPx;
                if (tracks[i].onObject && clean[i] && inCell) mask.at<std::uint8_t>(y, x) = 0;
            }
    cv::dilate(mask, mask, cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * growPx + 1, 2 * growPx + 1}));
    return mask & object;
}

// Dilating only the object's box and the growth's reach gives the frame-wide dilation's mask, for
// objects inside the frame, at its edges and touching a corner, with clean cells scattered over
// them.
TEST(IceMask, TheObjectsBoxGivesTheWholeFramesMask) {
    const cv::Size frame(240, 160);
    const cv::Rect objects[] = {{60, 40, 100, 70}, {0, 30, 90, 60}, {170, 100, 70, 60}, {0, 0, 240, 160}};
    cv::RNG random(7);
    for (const cv::Rect& box : objects) {
        cv::Mat object = cv::Mat::zeros(frame, CV_8UC1);
        cv::ellipse(object, (box.tl() + box.br()) / 2, box.size() / 2, 15.0, 0.0, 360.0, cv::Scalar(255), cv::FILLED);
        std::vector<TextureTrack> tracks;
        std::vector<std::uint8_t> clean;
        for (int y = 3; y < frame.height; y += 6)
            for (int x = 3; x < frame.width; x += 6) {
                if (!object.at<std::uint8_t>(y, x)) continue;
                TextureTrack t;
                t.pixel = {x, y};
                t.onObject = true;
                tracks.push_back(t);
                clean.push_back(random.uniform(0, 4) != 0 ? 1 : 0);  // a quarter of the cells may be ice
            }
        for (int grow : {0, 5, 40}) {
            const cv::Mat fast = iceMask(object, tracks, clean, 6, grow);
            const cv::Mat plain = iceMaskOverTheFrame(object, tracks, clean, 6, grow);
            EXPECT_EQ(cv::countNonZero(fast != plain), 0) << box << " grow " << grow;
            EXPECT_GT(cv::countNonZero(fast), 0);
        }
    }
}

}  // namespace
}  // namespace icewatch::volume
