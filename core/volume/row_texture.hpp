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
// faint texture away alike in every frame, so averaging the frames does not bring it back.
struct RowTextureOptions {
    int radiusPx = 6;  // the window the texture is taken over: the slanted window's
    // Texture along the rows above the image noise's own, grey levels per pixel (the rms of the
    // horizontal derivative over the window, the noise's share taken off), below which a pixel
    // is faint. Rendered beads read -85 and -123 % at 0.22-0.24 and -18 % at 0.34; leading-edge
    // horns, ridges and beads that read within their bars carry 0.7-1.5.
    double minGreyPerPx = 0.3;
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

// Per pixel of `grey` (CV_32F), the rms of the horizontal central difference over the
// (2r+1)² window, with the noise's share (noiseGrey² / 2) taken off; 0 where the noise is all.
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
    cv::Mat baselineObject;
    std::function<cv::Point2d(cv::Point2d)> toCurrent;
    double lightRatio = 1.0;
    cv::Mat thicknessMm;
};

// Where ice may be, in the current capture's pixels: where ice at least minIceMm thick was read,
// and where the object's texture along the rows was lost, which the matcher may have read as
// anything from no ice to much (the baseline carried at least minGreyPerPx and twice the texture
// that the light's change leaves, the current capture less than minGreyPerPx). Of those, the
// faint: lost, or read with less texture along the rows than minGreyPerPx. Each image's noise is
// its own, read over the baseline's object.
FaintIce faintIce(const RowTextureInputs& in, const RowTextureOptions& options);

}  // namespace icewatch::volume
