#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "core/volume/texture_tracks.hpp"

namespace icewatch::volume {

// Where the ice may be, in baseline left pixels (CV_8U, 255): the object's outline minus the
// cells of the samples whose texture was found again unchanged and moved with the object (`clean`,
// one flag per track; a cell is the stepPx square around its sample), grown by `growPx` and kept
// inside the outline. What the samples could not vouch for (no texture, near the outline, changed
// look, moved otherwise) counts as possible ice. The growth is the matcher's reach: its
// aggregation spreads the ice's disparity over the clean surface around it, and the volume it
// spreads there must still be counted.
cv::Mat iceMask(const cv::Mat& object, const std::vector<TextureTrack>& tracks, const std::vector<std::uint8_t>& clean,
                int stepPx, int growPx);

}  // namespace icewatch::volume
