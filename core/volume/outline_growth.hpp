#pragma once

#include <array>
#include <vector>

#include <opencv2/core.hpp>

#include "core/volume/height_grid.hpp"
#include "core/volume/registration.hpp"

namespace icewatch::volume {

// Ice grows along the surface's normals, so a layer over the whole object also wraps its edges and
// stands out of its outline there, on both long sides; a horn, a bead or rime patches stand out of
// one side or none. Against a featureless sky the outline is where the picture departs from the
// sky, and the camera does not move: how far that moved outwards between the captures, beyond
// what the object's motion moved it, is ice over the edges. Where the texture kept its look under
// such a layer (a clear glaze that brightens it as much as the sun dimmed), the texture is no
// evidence of the object's motion: the outline is.

struct OutlineGrowthOptions {
    int stationStepPx = 4;  // along the outline
    // Each station's profile along the outline's normal: this far in (the object shows) and out
    // (the sky beyond whatever stands on the edge), sampled every half pixel on three parallel
    // lines a pixel apart, averaged.
    int insidePx = 10;
    int outsidePx = 18;
    // The sky along a profile is a line fitted over its outer part (soft clouds have a gradient);
    // what departs from it by more than this, the same way for a pixel inwards, stands in front of it.
    int skyFitPx = 8;
    double departGrey = 3.0;
    // A station counts where the baseline's object stands against the sky by at least this much.
    double minObjectContrastGrey = 12.0;
    // Stations whose normal lies within this angle of the object's long axis are its ends (root,
    // tip): a long side is either of the two other directions.
    double endAngleDeg = 45.0;
    int minStationsPerSide = 20;
    // Both long sides' median growth beyond this: a layer over the edges. A clean edge of 21
    // rendered blades moved by 0.07 mm at most (clouds, gloss, roll, tilt, swing, 650-1400 mm, one
    // frame or 16); a motion wrong along the view by a glaze's thickness changes the outline's size
    // by 0.1-0.2 px; the clear glaze over the edges of seed 14 grew them by 2.3 and 5.2 mm.
    double minGrowthMm = 0.5;
};

struct OutlineGrowth {
    // Per long side of the object (0: the side its minor axis points to, 1: the other): the
    // stations measured against the sky and their median growth, mm on the object's plane.
    std::array<int, 2> stations{0, 0};
    std::array<double, 2> medianMm{0.0, 0.0};
    bool bothSidesGrew = false;
};

// `baselineGrey`, `currentGrey`: the left eyes (CV_32F, frame-sized); `roi`: the object (CV_8U);
// `featureless`: the featureless background beside it in the baseline (silhouette.hpp:
// featurelessBackground); `toBaseline`: the registered motion (current -> baseline) on `plane`;
// `k`: the rectified left camera; `valid`: where both images hold pixels (their matched windows).
OutlineGrowth outlineGrowth(const cv::Mat& baselineGrey, const cv::Mat& currentGrey, const cv::Mat& roi,
                            const cv::Mat& featureless, const PlaneFrame& plane, const RigidTransform& toBaseline,
                            const cv::Matx33d& k, const cv::Rect& valid, const OutlineGrowthOptions& options = {});

// Where a profile (inside first) departs from the sky, px from its first sample, or a negative
// value when its outer `skyFitSamples` are not sky or nothing departs from them: the outermost
// place that departs, the same way for a pixel inwards, by more than `departGrey`, placed where the
// departure is half of what it reaches within two pixels inwards. Exposed for its test.
double skyEdgeInProfile(const std::vector<float>& profile, double stepPx, int skyFitSamples, double departGrey);

}  // namespace icewatch::volume
