#pragma once

#include <functional>

#include <opencv2/core.hpp>

namespace icewatch::volume {

// Stereo reads depth from how the image changes along its rows (the epipolar lines): a surface
// whose brightness varies only across the rows, or not at all, gives the matcher nothing to place
// its disparity by, and the aggregation then carries the surface around it over it. Ice is where
// that bites: a bead along the leading edge, blurred by the lens and compressed by a tone curve,
// keeps its shading across the rows and loses its own faint texture along them. Its top was then
// read at the blade's depth around it (a 257 391 mm³ bead read -85 % and `ok` against ±37 %:
// 0.2 px too far where it was 3-6 mm thick, 0.7 px at 9-15 mm). The JPEG encoding quantises such
// faint texture away alike in every frame, so averaging the frames does not bring it back. The
// noise must be taken off what is read as texture, or a few frames' noise passes for it: on JPEG
// frames the image's second differences see an eighth of the noise power the horizontal
// difference does, so the noise is taken from a draw of each average's own noise instead.
struct RowTextureOptions {
    int radiusPx = 6;  // the window the texture is taken over: the slanted window's
    // Texture along the rows above the capture's own noise, grey levels per pixel (the rms of the
    // horizontal derivative over the window, the noise draw's power taken off), below which a
    // pixel is faint. Set on texture with the noise taken off: beads that read -85 to -100 %
    // stand at 33-49 % faint (4-64 frames), beads that read -18 to -29 % inside their bars at
    // 6-18 %, leading-edge horns and ridges at 0-1 %.
    double minGreyPerPx = 0.2;
    double minIceMm = 1.0;  // a pixel where the ice read at least this thick is ice
    int minIcePixels = 400;  // fewer ice pixels than this are not judged
    // A share of the ice's pixels faint beyond which its thickness is not measured but carried over
    // from around it.
    double maxFaintShare = 0.25;
};

// The image's noise, grey levels (1 σ), from its second differences where `mask` is set
// (Immerkær's operator, the 3 x 3 Laplacian difference, which cancels every surface up to a
// plane; the median of its absolute response rather than his mean, because the edges of ice
// and of the object answer it too: a horn's edges made the mean 2.7 times the baseline's on an
// unmoved blade under the same light, and the noise's share taken off the texture then left a
// third of the clean blade faint). 0 when the mask is empty.
double imageNoiseGrey(const cv::Mat& grey, const cv::Mat& mask);

// The power a noise draw (AveragedCapture::noise, rectified: Surface::leftNoise) shows in the
// horizontal central difference, per pixel: its local mean over the (2r+1)² window (CV_32F,
// grey levels² per pixel²). The image's noise has the same, whatever its spectrum.
cv::Mat rowNoisePower(const cv::Mat& noise, int radiusPx);

// Per pixel of `grey` (CV_32F), the rms of the horizontal central difference over the
// (2r+1)² window, with the noise's share (`noisePower`, CV_32F, per pixel) taken off; 0 where the
// noise is all. With a level `noiseGrey` instead, the noise is taken as white (its share σ²/2).
cv::Mat rowTextureGreyPerPx(const cv::Mat& grey, const cv::Mat& noisePower, int radiusPx);
cv::Mat rowTextureGreyPerPx(const cv::Mat& grey, double noiseGrey, int radiusPx);

struct FaintIce {
    int icePixels = 0;    // where ice may be: read at least minIceMm thick, or the texture lost
    int faintPixels = 0;  // of those, with less texture along the rows than minGreyPerPx
    int lostPixels = 0;   // of those, where the baseline's texture along the rows is gone
    double share() const { return icePixels > 0 ? double(faintPixels) / icePixels : 0.0; }
    // Whether so much of the ice is faint that its thickness cannot be taken as measured.
    bool unmeasured(const RowTextureOptions& o) const { return icePixels >= o.minIcePixels && share() > o.maxFaintShare; }
};

// The two captures as the stage reads them: their grey images (CV_32F, one size), the baseline's
// object (CV_8U, off its mixed edge), where each of its pixels lies in the current capture (the
// registered plane), the scene's change of light (current over baseline) and the current
// capture's thickness as read (CV_32F, mm, NaN where none was read).
struct RowTextureInputs {
    cv::Mat baselineGrey, currentGrey;
    cv::Mat baselineNoise, currentNoise;  // each capture's noise draw (empty: none)
    cv::Mat baselineObject;
    std::function<cv::Point2d(cv::Point2d)> toCurrent;
    double lightRatio = 1.0;
    cv::Mat thicknessMm;
    // The current capture's pixels where the trackers lost the object's texture and the current
    // capture's stereo cannot read what hid it (unreadLostTexture, CV_8U; may be empty): where no
    // ice was read there, lost too, whatever the rows' texture seems to be. The chain gives it for
    // a capture without a noise draw (a single frame), whose noise passes for texture.
    cv::Mat unreadLost;
};

// Where ice may be, in the current capture's pixels: where ice at least minIceMm thick was read,
// and where the object's texture along the rows was lost, which the matcher may have read as
// anything from no ice to much (the baseline carried at least minGreyPerPx and twice the texture
// that the light's change leaves, the current capture less than minGreyPerPx). Of those, the
// faint: lost, or read with less texture along the rows than minGreyPerPx. Each image's noise is
// its own: the power its noise draw shows, or without one white noise at the level its second
// differences give over the baseline's object. The pixels of `unreadLost` where no ice was read
// (under minIceMm) are lost as well.
FaintIce faintIce(const RowTextureInputs& in, const RowTextureOptions& options);

}  // namespace icewatch::volume
