#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "core/volume/texture_tracks.hpp"

namespace icewatch::volume {

// How far the stereo matcher's change of disparity between the captures departs from the texture
// tracks' on the object's clean texture. The tracks follow each patch alone; the matcher
// aggregates costs over windows and regularises along scanlines, and where the texture is weak
// against the noise its surface moves by a fraction of a pixel that is not there: more near the
// outline and beside the ice, and the more so the fewer frames were averaged. The volume
// integrates the matcher's surface, so this is an error of the volume that the tracks measure
// and the budget need not assume.
struct MatcherPush {
    double meanPx = 0;   // mean of (matcher - tracks) over the samples, current minus baseline
    double sigmaPx = 0;  // standard error of that mean (neighbouring samples counted as correlated)
    int samples = 0;
};

// Over the tracks in `use` (the clean evidence of the registration, or every track found again in
// both eyes) on the object that lie inside `possibleIce` (CV_8U, baseline left pixels), where the
// volume is integrated. Both disparity maps are the matcher's (CV_32F, frame-sized, negative where
// none); the current one is read at the track's current pixel, bilinearly where its four
// neighbours are valid. `correlationFactor`: how many samples share one independent error
// (overlapping patches).
MatcherPush matcherPush(const std::vector<TextureTrack>& tracks, const std::vector<std::uint8_t>& use,
                        const cv::Mat& baselineDisparity, const cv::Mat& currentDisparity,
                        const cv::Mat& possibleIce, double correlationFactor);

}  // namespace icewatch::volume
