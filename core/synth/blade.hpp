#pragma once

#include <cstdint>

#include "core/synth/geometry.hpp"
#include "core/synth/scene.hpp"

namespace icewatch::synth {

// A bead's reach over the suction side (mm), or the size of the ridges (their width and height for
// 1 mm), before bladeGeometry sizes it to the requested volume.
constexpr double kBeadReferenceMm = 10.0;

// The seed paper's model blade as a grid over its planform (x along the span, root at -x, y along
// the chord, leading edge at -y, h the suction side's height above the flat pressure side), with
// the ice of the given kind for amplitude 1 (its volume is scaled afterwards). A bead's ice is in
// mm already, for a bead reaching beadOverMm over the suction side, as high as the seed's
// proportions make it; so are the ridges' and the icicles' runback band, beadOverMm their size.
GridSurface bladeSurface(IceKind ice, std::uint32_t seed, double beadOverMm = kBeadReferenceMm);

// The part of a bead ice kind that stands in front of the leading edge: a grid over the chord
// plane from the leading edge forwards, all of it ice (its clean surface is nothing, so it is
// rendered iced only). Empty (nu = 0) for the other kinds. Its ice is scaled with the blade's.
GridSurface beadFront(IceKind ice, std::uint32_t seed, double beadOverMm = kBeadReferenceMm);

// Icicles hanging out of the trailing edge: a grid over the chord plane from the trailing edge
// outwards, ice only where an icicle hangs (each a half-cone towards the camera, its root as
// thick as it is half-wide, tapering to its tip), in mm for an icicle size of sizeMm: roots of
// 0.4 to 0.8 times the size in radius, lengths 3 to 7 times it (times lengthScale), so that much
// ice hangs far beyond the ring the chain watches around the outline; at a lengthScale of 0.25
// they are stubby, 0.75 to 1.75 times as long as their size, and a large volume stays within
// it. Their places and proportions by the seed.
GridSurface icicleFront(std::uint32_t seed, double sizeMm = kBeadReferenceMm, double lengthScale = 1.0);

// The glaze that wraps one edge of an iced blade (leading or trailing), out of its outline: for
// each span station of `blade` (its ice already scaled), a half-round of ice on the chord plane as
// wide and as high as the blade's ice at that edge, the section of a layer grown along the surface's
// normals around an edge. Its ice is in mm: it grows with the square of the blade's ice.
GridSurface glazeEdge(const GridSurface& blade, bool leading);

// glazeEdge's grid as rendered in the current capture (kMaterialGlazeEdge), shaded as the plane it
// lies on, since what shows through it is the light of what lies behind.
Mesh glazeEdgeMesh(const GridSurface& edge, const Pose& pose, const Look& look);

// The blade as rendered: clean (iceScale 0) or iced, posed in the camera frame; `material` the
// blade's, or kMaterialBeadFront for beadFront's grid. With refractive optics the iced blade carries
// its ice as a clear layer for the eyes to see the blade through (refraction.hpp).
Mesh bladeMesh(const GridSurface& s, double iceScale, const Pose& pose, const Look& look, int material = kMaterialBlade,
               IceOptics optics = IceOptics::Painted);

// The blade's outline on its flat side, leading edge root to tip then trailing edge tip to root,
// every stride-th grid point, posed in the camera frame.
std::vector<cv::Vec3d> bladeOutline(const GridSurface& s, const Pose& pose, int stride);

}  // namespace icewatch::synth
