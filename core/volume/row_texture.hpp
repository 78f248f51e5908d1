#pragma once

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
// (Immerkær's estimator: the mean absolute response of the 3 x 3 Laplacian difference operator,
// which cancels every surface up to a plane). 0 when the mask is empty.
double imageNoiseGrey(const cv::Mat& grey, const cv::Mat& mask);

// Per pixel of `grey` (CV_32F), the rms of the horizontal central difference over the
// (2r+1)² window, with the noise's share (noiseGrey² / 2) taken off; 0 where the noise is all.
cv::Mat rowTextureGreyPerPx(const cv::Mat& grey, double noiseGrey, int radiusPx);

struct FaintIce {
    int icePixels = 0;    // where ice at least minIceMm thick was read
    int faintPixels = 0;  // of those, with less texture along the rows than minGreyPerPx
    double share() const { return icePixels > 0 ? double(faintPixels) / icePixels : 0.0; }
    // Whether so much of the ice is faint that its thickness cannot be taken as measured.
    bool unmeasured(const RowTextureOptions& o) const { return icePixels >= o.minIcePixels && share() > o.maxFaintShare; }
};

// Of the current capture's pixels where the ice read at least minIceMm thick (`thicknessMm`, CV_32F,
// NaN where none was read), those whose texture along the rows of `grey` (CV_32F, the same size)
// is faint. The noise is `grey`'s over the pixels where thickness was read at all.
FaintIce faintIce(const cv::Mat& grey, const cv::Mat& thicknessMm, const RowTextureOptions& options);

}  // namespace icewatch::volume
