#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "core/common/ice.hpp"
#include "core/volume/texture_tracks.hpp"

namespace icewatch::volume {

struct ThicknessMap;

// Ice through which the object's own texture was seen.
//
// The object's texture is never on the outer surface of ice. Where the baseline's texture was
// found again in the current capture with its look changed otherwise than light changes it (a
// translucent layer whitens and veils it, a clear one brightens it), the cameras saw the object's
// surface through ice. Stereo sees that surface raised by refraction: by (1 − 1/n) of the layer's
// thickness looking along its normal (a quarter for ice), by more at oblique incidence, and by up
// to all of it where the layer's own surface shows too (a milky layer, frost on it, or a renderer
// that paints the texture on the ice). So such ice is between what the matcher read there and
// n/(n − 1) times it: a clear glaze on a table, rendered with refraction, read 34 % of its volume.
// Texture found again with its look unchanged but risen against the object's motion is not taken
// for it: a patch that an edge of opaque ice entered, or a motion the rigid model does not quite
// fit, does that too (beside a rendered ice block, 322 plate samples rose 0.6 mm).

// Per baseline left pixel (CV_8U, kSeenThrough): where the nearest texture sample on the object
// (`object`, the region) was found again with a changed look (TextureTrack::State::Changed). Nearest, so
// that every pixel of the object takes the word of one sample: opaque ice hides the texture of its
// samples, clean surface has its own.
// With `unchangedToo`, the samples found with their look unchanged say so as well: the object's
// unchanged texture as a whole brightened or darkened against the light (motion_evidence.hpp,
// MotionEstimate::objectLightShift), so a thin layer over all of it changed even what kept its
// look, only less (a clear glaze with wet highlights on a table, rendered with refraction: 258
// such samples beside 344 changed ones, and -42 % read as ok within +-76 990 mm3 without them).
// kGlimpsedThrough where the nearest sample is a track left unmeasured but glimpsed with its look
// changed (TextureTrack::glimpsed) and none of the eight samples around it (`stepPx` apart, the
// tracks' grid) kept its look: inside the ice, not at its edge. Under a clear layer refraction
// shifts the texture otherwise in each eye and the layer veils it, so its tracks fail their
// precision: a thick refractive glaze on a table, rendered, left about 450 of its 1 050 samples so, and
// read -43 % as ok within +-91 449 mm3 while only its measured samples counted as seen through.
// A glimpse is weaker evidence than a measured track (a patch half under an edge of opaque ice
// is glimpsed too), so such ice widens the uncertainty to what refraction may hide but does not
// move the estimate (seenThroughSigmaMm3).
inline constexpr std::uint8_t kSeenThrough = 255;
inline constexpr std::uint8_t kGlimpsedThrough = 128;
cv::Mat seenThroughPixels(const cv::Mat& object, const std::vector<TextureTrack>& tracks, int stepPx,
                          bool unchangedToo = false);

// How much thicker than what stereo sees ice may be when the texture was seen through it.
inline constexpr double kSeenThroughFactor = kIceRefractiveIndex / (kIceRefractiveIndex - 1.0);

// The ice the matcher read where the texture was seen through it (ThicknessMap::seenThrough).
struct SeenThroughIce {
    double readMm3 = 0;  // integrated over those nodes, as the matcher read it (≥ 0)
    int nodes = 0;
    double glimpsedReadMm3 = 0;  // the same over the nodes glimpsed through (kGlimpsedThrough)
    int glimpsedNodes = 0;
};
SeenThroughIce seenThroughIce(const ThicknessMap& map);

// What the estimate adds, and its 1 σ: such ice is between what was read and kSeenThroughFactor
// times it; the estimate takes the middle, the budget the rest of the interval. Not as a uniform
// spread over it (half-width/√3): a layer shows either the surface under it (clear, refracted) or
// its own (milky, frosted, painted), so the ice lies at one end or the other, and the half-width
// is its 1 σ. The read at either end carries errors of its own besides: a painted glaze on a table
// under light at 0.7, rendered, read 13 % over its truth, and with the uniform's σ was reported
// +148 % at 0.93 of its uncertainty.
// The share is of the ice seen through alone; the σ of it and of the ice glimpsed through, whose
// estimate is what was read (the interval's lower end: the same σ, at k = 2, reaches its upper).
double seenThroughShareMm3(const SeenThroughIce& seen);
double seenThroughSigmaMm3(const SeenThroughIce& seen);

}  // namespace icewatch::volume
