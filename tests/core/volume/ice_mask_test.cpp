#include "core/volume/ice_mask.hpp"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

namespace icewatch::volume {
namespace {

constexpr int kStep = 6;

// Samples on the lattice the trackers use, every kStep px inside `object`; `clean` decides each one.
template <class Decide>
void sampleLattice(const cv::Mat& object, std::vector<TextureTrack>& tracks, std::vector<std::uint8_t>& clean,
                   Decide decide) {
    for (int y = kStep / 2; y < object.rows; y += kStep)
        for (int x = kStep / 2; x < object.cols; x += kStep) {
            if (!object.at<std::uint8_t>(y, x)) continue;
            TextureTrack t;
            t.pixel = {x, y};
            t.onObject = true;
            t.state = TextureTrack::State::Unchanged;
            tracks.push_back(t);
            clean.push_back(decide(x, y, tracks.back()) ? 1 : 0);
        }
}

// The mask by its definition, pixel by pixel, over the whole frame: a sample vouches when it is
// clean, or unchanged in look with fewer than two of its eight lattice neighbours not clean; a
// pixel in a vouching sample's cell is clean, in another sample's cell possible ice, in no cell as
// its nearest cell; the possible ice dilated by the disc, cut back to the object.
cv::Mat iceMaskByDefinition(const cv::Mat& object, const std::vector<TextureTrack>& tracks,
                            const std::vector<std::uint8_t>& clean, int growPx) {
    std::vector<std::uint8_t> vouches(clean.size());
    for (std::size_t i = 0; i < tracks.size(); ++i) {
        int others = 0;
        for (std::size_t k = 0; k < tracks.size(); ++k) {
            const cv::Point d = tracks[k].pixel - tracks[i].pixel;
            const bool neighbour = k != i && std::abs(d.x) <= kStep && std::abs(d.y) <= kStep;
            if (neighbour && !clean[k]) ++others;
        }
        vouches[i] = clean[i] || (tracks[i].state != TextureTrack::State::Changed && others < 2);
    }
    auto inCell = [&](const TextureTrack& t, int x, int y) {
        const cv::Point corner = t.pixel - cv::Point(kStep / 2, kStep / 2);
        return x >= corner.x && x < corner.x + kStep && y >= corner.y && y < corner.y + kStep;
    };
    cv::Mat mask = cv::Mat::zeros(object.size(), CV_8UC1);
    for (int y = 0; y < mask.rows; ++y)
        for (int x = 0; x < mask.cols; ++x) {
            if (!object.at<std::uint8_t>(y, x)) continue;
            double nearestClean = std::numeric_limits<double>::infinity(), nearestOther = nearestClean;
            bool covered = false, ice = false;
            for (std::size_t i = 0; i < tracks.size(); ++i) {
                if (inCell(tracks[i], x, y)) {
                    covered = true;
                    ice = !vouches[i];
                }
                // The distance to the cell's nearest pixel.
                const cv::Point corner = tracks[i].pixel - cv::Point(kStep / 2, kStep / 2);
                const double dx = std::max({corner.x - x, 0, x - (corner.x + kStep - 1)});
                const double dy = std::max({corner.y - y, 0, y - (corner.y + kStep - 1)});
                double& nearest = vouches[i] ? nearestClean : nearestOther;
                nearest = std::min(nearest, std::hypot(dx, dy));
            }
            if (!covered) ice = !(nearestClean < nearestOther);
            if (ice) mask.at<std::uint8_t>(y, x) = 255;
        }
    if (growPx > 0) {
        cv::dilate(mask, mask, cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * growPx + 1, 2 * growPx + 1}));
    }
    return mask & object;
}

cv::Mat ellipseObject(const cv::Size& frame, const cv::Rect& box) {
    cv::Mat object = cv::Mat::zeros(frame, CV_8UC1);
    cv::ellipse(object, (box.tl() + box.br()) / 2, box.size() / 2, 15.0, 0.0, 360.0, cv::Scalar(255), cv::FILLED);
    return object;
}

// The mask as made (the object's box dilated, the rim by distance transforms) is the mask by its
// definition, for objects inside the frame, at its edges and touching a corner, with clean cells,
// ice, lone noise and changed looks scattered over them.
TEST(IceMask, IsTheMaskByItsDefinition) {
    const cv::Size frame(240, 160);
    const cv::Rect objects[] = {{60, 40, 100, 70}, {0, 30, 90, 60}, {170, 100, 70, 60}, {0, 0, 240, 160}};
    cv::RNG random(7);
    for (const cv::Rect& box : objects) {
        const cv::Mat object = ellipseObject(frame, box);
        std::vector<TextureTrack> tracks;
        std::vector<std::uint8_t> clean;
        sampleLattice(object, tracks, clean, [&](int, int, TextureTrack& t) {
            if (random.uniform(0, 8) == 0) t.state = TextureTrack::State::Changed;
            return t.state == TextureTrack::State::Unchanged && random.uniform(0, 4) != 0;
        });
        for (int grow : {0, 5, 12}) {
            const cv::Mat made = iceMask(object, tracks, clean, kStep, grow);
            const cv::Mat plain = iceMaskByDefinition(object, tracks, clean, grow);
            EXPECT_EQ(cv::countNonZero(made != plain), 0) << box << " grow " << grow;
            EXPECT_GT(cv::countNonZero(made), 0);
        }
    }
}

// Ice on one end of an object: the mask covers it and its reach, and nothing of the clean end, rim
// included. A lone sample that was not clean but kept its look is noise; a lone changed look is not.
TEST(IceMask, CoversTheIceAndItsReachNotTheCleanSurfaceBesideIt) {
    const cv::Size frame(240, 120);
    const cv::Mat object = ellipseObject(frame, {10, 10, 220, 100});
    std::vector<TextureTrack> tracks;
    std::vector<std::uint8_t> clean;
    const cv::Point lone(153, 63), changed(189, 57);
    sampleLattice(object, tracks, clean, [&](int x, int y, TextureTrack& t) {
        if (cv::Point(x, y) == changed) t.state = TextureTrack::State::Changed;
        return x >= 60 && cv::Point(x, y) != lone && cv::Point(x, y) != changed;
    });
    const int grow = 12;
    const cv::Mat mask = iceMask(object, tracks, clean, kStep, grow);
    // The iced end (x < 60, up to its half cell) and the reach beyond it, to its outline.
    for (int y = 0; y < frame.height; ++y)
        for (int x = 0; x < frame.width; ++x) {
            if (!object.at<std::uint8_t>(y, x)) continue;
            if (x < 57 + grow - 1) {
                EXPECT_TRUE(mask.at<std::uint8_t>(y, x)) << x << "," << y;
            }
            // A cell reaches kStep / 2 px from its sample, the growth `grow` beyond.
            const bool nearChanged = std::hypot(x - changed.x, y - changed.y) <= grow + kStep;
            if (x > 60 + grow && !nearChanged) {
                EXPECT_FALSE(mask.at<std::uint8_t>(y, x)) << x << "," << y;
            }
        }
    EXPECT_FALSE(mask.at<std::uint8_t>(lone));
    EXPECT_TRUE(mask.at<std::uint8_t>(changed));
}

}  // namespace
}  // namespace icewatch::volume
