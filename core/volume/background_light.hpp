#pragma once

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/volume/texture_tracks.hpp"

namespace icewatch::volume {

// The scene's change of light between the captures, taken from what cannot be ice: the
// background around the object (a sky, a table). A change of light scales the background and the
// object alike; a layer of ice over the whole object brightens the object alone. Taken from the
// object itself, the change of light would be the ice's, and a uniform white layer over
// everything would pass for a cloud.
struct BackgroundLightOptions {
    int marginPx = 40;       // kept from the object's outline (its motion, its blur, its shadow)
    int minPixels = 2000;    // fewer background pixels than this: no answer
    float lowestGrey = 8;    // darker or ...
    float highestGrey = 247; // ... brighter in either capture says nothing of the light (clipped)
};

// Mean grey of the current capture over the baseline's, over the pixels both hold (`baselineWindow`
// and `currentWindow`, the frame's parts each grey image holds) outside `roi` (CV_8U, the object in
// baseline pixels) grown by the margin. Empty when too few pixels are left.
std::optional<double> backgroundLightRatio(const cv::Mat& baselineGrey, const cv::Mat& currentGrey, const cv::Mat& roi,
                                           const cv::Rect& baselineWindow, const cv::Rect& currentWindow,
                                           const BackgroundLightOptions& options = {});

// For a refusal's reason: when the object's texture (the median over its tracks found again)
// changed its brightness against the background's light by more than `maxChange`, a sentence
// saying so; empty otherwise.
std::string objectLightNote(const std::vector<TextureTrack>& tracks, std::optional<double> lightRatio,
                            double maxChange);

}  // namespace icewatch::volume
