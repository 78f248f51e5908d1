#pragma once

#include <array>
#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "core/volume/height_grid.hpp"
#include "core/volume/registration.hpp"

namespace icewatch::volume {

// Ice grows along the surface's normals, so a layer over the whole object also wraps its edges and
// stands out of its outline there, on both long sides; a horn, a bead or rime patches stand out of
// one side or none. Against a featureless sky the camera does not move, and how much of each
// profile across the outline the object covers (its width, weighted by how far each sample departs
// from the sky towards the object's grey) changes between the captures, beyond what the object's
// motion changed it, only where something stands on the edge. Where the texture kept its look
// under such a layer (a clear glaze that brightens it as much as the sun dimmed), the texture is no
// evidence of the object's motion: the outline is.
//
// Why a covered width and not the edge's place: blur spreads an edge but keeps what it covers, and
// a clear layer over the edge shows the sky behind it, brighter or darker than the object's grey.
// Placed by a threshold, the edge of seed 14's glaze grew 2.7 mm blurred by 1.5 px and shrank 0.8
// mm blurred by 1.8 (its bright rim and the dark edge beside it cancelling), passing through zero
// on the way; covered width reads the rim as a share of the object's contrast at any blur.

struct OutlineGrowthOptions {
    int stationStepPx = 4;  // along the outline
    // Each station's profile along the outline's normal: this far in (the object shows) and out
    // (the sky beyond whatever stands on the edge), sampled every half pixel on three parallel
    // lines a pixel apart, averaged. Every length here widens with the baseline's blur beyond
    // `blurForLengthsPx`, so that a blurred edge's tails stay inside the profile.
    int insidePx = 10;
    int outsidePx = 18;
    // The sky along a profile is a line fitted over its outer part (soft clouds have a gradient);
    // a profile whose outer part departs from it by more than this is not against the sky.
    int skyFitPx = 8;
    double departGrey = 3.0;
    // A station counts where the object stands against the sky by at least this much (the inner
    // half of the inside, at the median), in both captures.
    double minObjectContrastGrey = 12.0;
    // The baseline's blur (edge_blur.hpp), and the blur the lengths above are made for.
    double blurPx = 0.0;
    double blurForLengthsPx = 2.0;
    // Stations whose normal lies within this angle of the object's long axis are its ends (root,
    // tip): a long side is either of the two other directions.
    double endAngleDeg = 45.0;
    int minStationsPerSide = 20;
    // Both long sides' median change beyond this, either way: a layer over the edges, or a motion
    // that is not the object's. On 40 rendered blades (leading edges, beads, ridges, shed ice, rime
    // patches; blurred by up to 3 px, light 0.8-1.2, gloss, drifting clouds, rolled, tilted,
    // swung, 650-1400 mm, a power law, a low sun) the side without ice changed by 0.08 mm at most
    // (a rime patch reaching an edge by 0.52); the clear glaze over the edges of seed 14 changed
    // them by -0.8 to -0.9 and -2.9 mm, sharp or blurred by up to 3 px.
    double minChangeMm = 0.5;
};

struct OutlineGrowth {
    // Per long side of the object (0: the side its minor axis points to, 1: the other): the
    // stations measured against the sky and the median change of the width the object covers
    // there, mm on the object's plane (positive: it covers more, as opaque ice darker or brighter
    // than the sky; negative: the sky shows brighter or darker through what now stands there than
    // the object's grey would, as through a clear layer, or the edge moved in).
    std::array<int, 2> stations{0, 0};
    std::array<double, 2> medianMm{0.0, 0.0};
    bool bothSidesChanged = false;
};

// `baselineGrey`, `currentGrey`: the left eyes (CV_32F, frame-sized); `roi`: the object (CV_8U);
// `featureless`: the featureless background beside it in the baseline (silhouette.hpp:
// featurelessBackground); `toBaseline`: the registered motion (current -> baseline) on `plane`;
// `k`: the rectified left camera; `valid`: where both images hold pixels (their matched windows).
OutlineGrowth outlineGrowth(const cv::Mat& baselineGrey, const cv::Mat& currentGrey, const cv::Mat& roi,
                            const cv::Mat& featureless, const PlaneFrame& plane, const RigidTransform& toBaseline,
                            const cv::Matx33d& k, const cv::Rect& valid, const OutlineGrowthOptions& options = {});

// The width, px, that the object covers in a profile across its outline (inside first, sampled
// every `stepPx`): the sum over the samples between the inside's inner `insideSamples` and the
// outer `skyFitSamples` of each one's departure from the sky's line (fitted over the outer
// samples) over the object's (the inside's median departure), times the step. Blur moves coverage
// along the profile but keeps its sum. Empty when the outer samples are not sky (one departs by more
// than `departGrey`) or the object stands out of the sky by less than `minContrastGrey`. Exposed
// for its test.
std::optional<double> coveredWidthPx(const std::vector<float>& profile, double stepPx, int insideSamples,
                                     int skyFitSamples, double departGrey, double minContrastGrey);

}  // namespace icewatch::volume
