#pragma once

#include "core/volume/matcher_push.hpp"
#include "core/volume/motion_evidence.hpp"
#include "core/volume/parameters.hpp"
#include "core/volume/seen_through.hpp"
#include "core/volume/thickness_map.hpp"

namespace icewatch::volume {

// The volume's error budget, each part 1 σ, mm³.
struct UncertaintyBudget {
    double noiseMm3 = 0;          // per-point depth noise over the independent samples
    double registrationMm3 = 0;   // the registration's own uncertainty, propagated
    double trackingMm3 = 0;       // a bias of the texture trackers common to every sample
    double pushMm3 = 0;           // the matcher's change departing from the tracks' (matcher_push.hpp)
    double biasMm3 = 0;           // systematic sub-pixel disparity bias
    double edgeMm3 = 0;           // where the ice's edges are
    double fatteningMm3 = 0;      // the ice's nearer disparity carried over the surface beside or behind it
    double outlineMm3 = 0;        // ice at the outline: the footing of what stands out of it, what may
                                  // stand out of it unseen (beyond_outline.hpp), and the matcher's
                                  // pull beside what stands out of it against featureless sky
    double scaleMm3 = 0;          // the depth scale and the matcher's response on ice, relative to the volume
    double seenThroughMm3 = 0;    // ice the object's texture was seen through: refraction (seen_through.hpp)
    double hiddenMm3 = 0;         // bands hidden along the line of sight, bridged (ThicknessMap::hiddenMm)
};

// What the camera makes of a millimetre at the object's distance.
struct ViewGeometry {
    double focalPx = 0;
    double baselineMm = 0;
    double depthMm = 0;  // of the object's plane
    // How far (px) the surface's measurement may carry an occluding edge's disparity over the
    // surface behind it: the slanted window's radius, or the matcher's reach. 0 where the object
    // faces the camera and the ice's edges occlude next to nothing.
    double fatteningPx = 0;
    // How much more the captures are blurred than their pixels, px (edge_blur.hpp): a blurred step
    // carries its nearer disparity that much further, whether the object faces the camera or not.
    double blurPx = 0;
};

// Each error source carried to the volume integrated over the ice nodes of `map`:
//   noise         per-point depth noise (disparity_noise_px), averaged over the independent
//                 samples on the ice (the matcher's errors are correlated over correlation_px);
//   registration  the larger of the motion's covariance and its jackknife (a motion leaning on one
//                 end of the object, or on evidence that is not quite rigid, shows in how it moves
//                 when a band of the evidence is left out, not in its covariance), through the
//                 thickness each node would gain from a small motion;
//   tracking      a disparity-change bias common to every texture track (track_bias_px): the
//                 registration's covariance and jackknife see the tracks' scatter, not a bias they
//                 share, and a shared bias moves the whole registered surface along the view;
//   push          the matcher's change of disparity against the tracks' where the volume is
//                 integrated (matcher_push.hpp), on the clean texture or on every texture found
//                 again, whichever departs more: its mean over the ice area, with the mean's
//                 own standard error in quadrature
//                 (the scatter of single samples is the noise the other terms carry);
//   bias          a systematic sub-pixel disparity bias (subpixel_bias_px) over the ice area;
//   edge          a shift of σ_e of every edge of height H and length L moves σ_e·H·L, i.e.
//                 σ_e·∫|∇t|; the noise floor of |∇t| (its median) is taken off so that noise does
//                 not pass for edges;
//   fattening     on an object seen at an angle, the ice's edges stand in front of the surface
//                 behind them, and a window centred on that surface takes the ice's nearer
//                 disparity (foreground fattening): every edge may reach out by as much as
//                 view.fatteningPx and, where the windows gave up beside the step, further: that
//                 reach is the σ, on the same ∫|∇t|; facing the camera too, a step lower than
//                 the windows' weights can see (fatteningSeparableStepPx) carries the ice's
//                 disparity over the surface beside it: facingFatteningPx, on ∫|∇t| with the
//                 thickness capped at that step's height; the larger of the two; both reach
//                 blur_fattening_per_px times the captures' blur further (view.blurPx);
//   scale         scale_uncertainty_percent of the volume;
//   seen through  ice the object's texture was seen through may be up to n/(n − 1) times as thick as
//                 stereo sees it (seenThroughSigmaMm3);
//   hidden        a band the camera does not see along its line of sight, bridged by the
//                 interpolation, may be anything from the far surface to the near one: the bridge
//                 is the middle, uniformly (|hiddenMm| integrated, over √3); so is the underside of
//                 ice in front of an outline that stands off its background.
UncertaintyBudget volumeUncertainty(const ThicknessMap& map, const PlaneFrame& plane, const MotionEstimate& motion,
                                    const MatcherPush& push, const ViewGeometry& view, const Parameters& parameters,
                                    double volumeMm3, const SeenThroughIce& seenThrough = {});

// coverage · √(Σ parts²).
double expandedUncertainty(const UncertaintyBudget& budget, double coverageFactor);

}  // namespace icewatch::volume
