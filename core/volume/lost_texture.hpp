#pragma once

#include <functional>
#include <vector>

#include <opencv2/core.hpp>

#include "core/volume/texture_tracks.hpp"

namespace icewatch::volume {

// Texture the trackers lost, and whether stereo reads what hid it. Where the baseline's texture
// is not found again in the current capture, something covers it: opaque ice, or ice too plain
// to show it. The matcher's surface there is then the ice's own surface only if the current
// capture's two eyes carry texture enough to place it; where they do not, the aggregation
// carries the blade's surface around it over the ice. Judged by a patch of the current
// capture's left eye found again in its right eye, as precisely as texture evidence must be:
// this needs no model of the image's noise, which a single frame cannot tell from texture (its
// JPEG noise is not white). A leading-edge horn rendered with faint texture through a filmic
// curve, one frame a capture: 15 of the 240 samples it hid read precisely in the current
// capture, and the matcher read the horn as bare blade (-101 % and `ok`); at 16 frames all 239.
// The chain asks for it where a capture has no noise draw, whose rows row_texture.cpp cannot
// judge, and counts it there only where no ice was read (faintIce).

// The current capture's pixels (cells of stepPx around each place) where the object's texture
// was lost and the current capture's stereo cannot read the surface that hid it. A sample counts
// when it is on the object, the baseline's own stereo track found it (its texture was there to
// follow), and it was neither found again nor glimpsed (TextureTrack::State::Untracked, not
// glimpsed). Its place in the current capture is `toCurrent` of its baseline pixel; there the
// left patch is tracked along the row into the current right image from the matcher's
// disparity (CV_32F in `current.disparity`, ±2 px), and the surface is unread when the patch is
// not found or its shift is less precise than options.maxShiftSigmaPx. CV_8U, 255, frame-sized.
cv::Mat unreadLostTexture(const std::vector<TextureTrack>& tracks, const RectifiedCapture& current,
                          const std::function<cv::Point2d(cv::Point2d)>& toCurrent, const TextureTrackOptions& options);

}  // namespace icewatch::volume
