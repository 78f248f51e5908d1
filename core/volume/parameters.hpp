#pragma once

#include <vector>

#include "core/stereo/matcher.hpp"

namespace icewatch::volume {

enum class Integration {
    Trapz,  // trapezoidal rule over x, then over y (the seed paper's choice)
    Sum,    // V = Σ Z_ij·Δx·Δy
};

// Every tunable of the volume chain, with its default. Set from the configuration file's "volume"
// section (config/icewatch.json documents each key).
struct Parameters {
    // --- matching ---
    stereo::Method stereoMethod = stereo::Method::Paper;
    int maxDisparity = 128;  // disparities searched: 0 .. maxDisparity-1
    // The thickest ice a capture after the baseline must see: the band of disparities searched
    // reaches this far in front of the baseline's surface (match_region.cpp). Thicker ice reads
    // as invalid disparities there (a refusal for too few), never as a wrong depth.
    double maxIceThicknessMm = 60;
    // Captures after the baseline matched only in its region and band, a baseline with an outline
    // only around it (match_region.hpp); false: every capture over the whole frame and every
    // disparity (the comparison benchmark's "full frame").
    bool matchRegion = true;
    // The matcher's disparities measured again on the averaged images with a window that leans
    // with the surface (slanted_refinement.hpp): the matcher's staircase on a curved or turned
    // surface, and its push of the clean surface beside the ice, fall elsewhere once ice changed
    // the shape, and read as ice or as ice gone. The window's radius, and the standard error
    // above which the matcher's value stands.
    bool slantedWindow = true;
    int slantedWindowRadiusPx = 6;
    double slantedWindowMaxSigmaPx = 0.1;
    // Not configurable: the stage as it was before it was made fast, the plain kernel over the
    // whole region's box, every window fitted to its end (`icewatch volume --compare-slanted`).
    bool slantedWindowAsBefore = false;

    // --- region of interest ---
    // The object's outline in left-eye pixels of the camera frame as x0, y0, x1, y1, ...; empty:
    // segment it from the baseline capture (the largest surface at the dominant depth).
    std::vector<double> roiPolygon;
    int edgeMarginPx = 3;             // points this close to the outline are not measured (mixed depths)
    double segmentationBandMm = 150;  // segmentation: depth band around the dominant depth

    // --- registration (current capture onto the baseline, from unchanged texture) ---
    int trackRadiusPx = 8;            // texture patches are (2r+1)² pixels
    int trackStepPx = 6;              // one texture sample every this many pixels
    int trackSearchPx = 8;            // how far a patch may move between the captures beyond the global shift
    int minEvidenceSamples = 12;      // unchanged texture samples a motion may rest on
    double backgroundBandMm = 400;    // background within this depth of the object may hold it (a table, a rig)
    double maxRegistrationMm = 30;    // a larger movement is refused (the camera or blade moved)
    // The unchanged object texture that fixed the registration must span at least this share of
    // the object along both of its in-plane axes (tenths of its extent where the support holds a
    // third of the samples), unless a background it rests on fixes it.
    double minSupportSpanPercent = 25;
    // Where the object's texture alone fixes its motion (no background agrees with it), how
    // unevenly its unchanged samples may have changed their brightness, percent of their median
    // (the middle half's spread; motion_evidence.hpp, MotionEvidenceOptions::maxObjectAloneLightSpread).
    double maxObjectAloneLightSpreadPercent = 0.4;
    // The possible-ice mask grows by this much around what texture could not vouch for: the reach
    // of the slanted window (twice its radius), which spreads the ice's volume that far. Without
    // slanted windows the matcher's cross arms spread it further, and that reach is used.
    int iceMaskGrowPx = 12;
    // Ice beyond the outline (beyond_outline.hpp): a bead or a horn on the leading edge stands
    // out of the clean outline. The current surface is looked at this far around the outline
    // (0: not at all); a part of it that touches the object counts when it rises somewhere this
    // far above the surface it grows from (what the baseline saw there, or the outline's nearest
    // measured surface where it saw sky), several times the depth noise of an averaged capture
    // (and at least four times the noise the ring shows); that footing, where not seen, is known
    // to +- outlineFootingMm (1 sigma: the edge margin's pixels on a rounded edge).
    double outlineGrowthMm = 50;
    double outlineIceMinMm = 2.0;
    double outlineFootingMm = 1.5;
    // Where the outline stands more than this above the background the baseline saw beyond it (a
    // blade on trestles over its table), ice standing in front of it is measured from halfway
    // down, its underside anywhere from the outline's height to the background (the hidden term).
    // Lying on its table, a rendered blade's outline (its nearest measured surface, the edge margin
    // up a rounded edge) stood 1.0-4.0 mm above it (10th-90th percentile, under a bead); a plate
    // around a block, -1.5 to 1.2 mm.
    double outlineStandoffMm = 5.0;
    // Only pixels of the ring whose disparity is a measurement count (beyond_outline.hpp:
    // measurableRing): a textured patch (grey levels, on the trackers' smoothed image) found again
    // in the right eye.
    double outlineMinTextureGrey = 1.0;
    double outlineMinCorrelation = 0.7;
    // Where the baseline saw bare background beside the outline, the ice standing there is seen by
    // what it hides (silhouette.hpp): a pixel whose grey changed by at least this much (and four
    // times the background's own change).
    double outlineMinContrastGrey = 3.0;
    // Beside the ice seen that way, the matcher read the outline against the ice in the current
    // capture and against the sky in the baseline, whose featureless pixels it fills with an
    // arbitrary depth: its aggregation pulls the outline's surface towards it within this many
    // pixels (on a rendered bead, against the truth: the baseline 0.15 px nearer at 2-4 px from
    // the outline, 0.03 px at 10-12 px, the current capture within 0.03 px throughout).
    int outlineFringePx = 12;
    // Ice seen only by the background it hides is tapered from the outline's height over the
    // background it hides: a bead seen from the front. On an object turned out of the view by
    // more than this (silhouette.hpp: viewObliquityDeg), a bead's height shows as reach and its
    // reach hides behind it: the chain refuses. A rendered bead on a blade turned 30° away read
    // -74 % and -92 % outside its uncertainty there (the object's plane 17° out of the view); the
    // blades face the camera within 10°.
    double outlineMaxObliquityDeg = 15.0;

    // --- outlier filter (the seed paper, section 2.2) ---
    int knnK = 8;             // neighbours in the plane
    double knnTheta = 2.0;    // |z_i - mean| > θ·σ removes the point

    // --- grid and integration ---
    double gridCellMm = 1.0;  // Δx = Δy target; N = extent / cell + 1, then Δ = extent / (N - 1)
    Integration integration = Integration::Trapz;
    double maxThicknessMm = 200;  // a current point farther in front of the baseline is not ice
    // Occlusion steps (height_grid.hpp): a lattice triangle with an edge rising more than
    // occlusionStepMm and more than occlusionSlope times its length in the plane bridges ground
    // hidden behind a nearer surface; the far surface is continued under it instead of a ramp.
    // 8 mm is several times the depth noise between neighbouring pixels at 0.85 m (~2 mm); a
    // slope of 4 (76°) is steeper than any surface this camera measures head-on. 0: off.
    double occlusionSlope = 4.0;
    double occlusionStepMm = 8.0;

    // --- uncertainty ---
    double disparityNoisePx = 0.1;  // a-priori σ_d of one disparity (the data may show more)
    int correlationPx = 5;          // disparities are correlated over about this many pixels (matcher window)
    double subpixelBiasPx = 0.004;  // systematic sub-pixel disparity bias left after differencing
    // A disparity-change bias shared by every texture track, px (1 σ). Measured on rendered blades
    // against their true motion: 0.005-0.013 px with 64-frame captures, whatever the noise (its
    // cause is not known), which moved a 97 609 mm³ blade's volume by up to 13 %.
    double trackBiasPx = 0.01;
    double edgeUncertaintyPx = 0.5; // where an edge of the ice is, ± this
    // Facing the camera, a step of the ice too low for the slanted window's weights to see (its
    // disparity under fatteningSeparableStepPx) still carries the ice's disparity over the clean
    // surface beside it: within 5 px of such a step the surface read 20-37 % of the step too near,
    // within 10 px 5-8 %, on rendered ice blocks of 10-31 mm and on sheets of ice left by
    // shedding, each ending in a sharp step (2-12 mm): an error of 1.7-3.2 px times the steps'
    // height and length, all of it high (blocks of 80 000-250 000 mm³ +6 to +22 %, sheets +7 to
    // +26 %). Steps taller than this the windows' weights see: the error per px falls to 0.9 at
    // 1.8 px and 0.3 at 2.6 px. σ, px, over the steps' height up to the separable one.
    double facingFatteningPx = 2.0;
    double fatteningSeparableStepPx = 1.5;
    // The captures blurred beyond their pixels by b px (edge_blur.hpp) carry every step this many
    // times b further (rendered shed sheets on a table, blurred by 2 px: +53 % against +12 % sharp).
    double blurFatteningPerPx = 1.0;
    // A share of the volume itself (1 σ): the depth scale (the calibration's focal length and
    // baseline) and the matcher's response on ice, whose aggregation rounds a layer off; on
    // rendered blades a thin glaze over the whole blade read up to 9 % short.
    double scaleUncertaintyPercent = 4.0;
    double coverageFactor = 2.0;    // expanded uncertainty = k·σ (k = 2: about 95 %)

    // --- quality gate ---
    double minValidPercent = 50;      // valid disparities in the region
    double minMeanGrey = 25;          // mean grey level in the region (0..255)
    double maxSaturatedPercent = 20;  // pixels at >= 250
    // Clipped white where the baseline was not: ice (or the light on it) so bright that its texture
    // is gone, and the matcher fills its surface in from around it. A bead of white ice under light
    // 1.23 times the baseline's, 79 % of it clipped, read -58 % as ok within ±86 471 mm³ while the
    // region stayed under maxSaturatedPercent (18.7 %). Percent of the region, current less baseline.
    double maxNewSaturatedPercent = 5;
    // The region's texture: its mean gradient magnitude, grey levels per pixel. Under minContrast
    // the matcher has too little to measure the surface at all. Under minContrastObjectMotion the
    // texture is too faint to rest the motion on the object's own texture alone: a tone curve (a
    // camera's power law, a renderer's filmic curve) or a blur flattens it, and shrinks what a
    // clear glaze does to its look as well, so that a change of light cancels the rest; with the
    // gate at 0.7 for every scene, glazes against the sky read -64.8 to -95.7 % as ok. A background
    // the object rests on (a table, a plate) fixes the motion without the texture's look: measured
    // down to minContrast. Through a filmic curve a blade on a table reads 0.45-0.69: at 0.7 every
    // one was refused, its beads having read -50.8 % outside +-97 141 mm3 where they stood out of
    // the outline plain white. Since the table they hide tells them (silhouette.hpp), 0.5-0.69
    // read inside on every one rendered (-34 to +53 %) or were refused for another reason.
    double minContrast = 0.5;
    double minContrastObjectMotion = 1.0;
    int minPoints = 2000;             // points left to build each surface
    double maxFilledPercent = 40;     // grid area interpolated from no measurement at all
};

}  // namespace icewatch::volume
