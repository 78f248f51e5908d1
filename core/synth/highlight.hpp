#pragma once

#include "core/synth/rasterizer.hpp"
#include "core/synth/scene.hpp"

namespace icewatch::synth {

// Highlights. A glossy surface mirrors the light towards an eye where its normal halves the angle
// between the light and that eye (Blinn-Phong). So each eye sees a highlight at another place on a
// curved surface, and the highlight is not fixed to the surface: stereo matches it at another depth
// than the surface's, and it slides over the surface when the object or the light moves. Wet glaze
// is glossy, the blade's coat less so; rime, wood and the plate are matte.

struct Gloss {
    double strength = 0;  // the highlight's peak, in the light's units (0: matte)
    double exponent = 1;  // Blinn-Phong: the larger, the smaller and sharper the highlight
};

// How glossy a vertex of this material is, under ice of `thicknessMm` of this kind, for a scene
// whose glaze mirrors `gloss` of the light at its peak.
Gloss surfaceGloss(int material, IceKind ice, double thicknessMm, double gloss);

// Sets kAttributeHighlight on every vertex of `mesh` for the eye at (eyeCentreXMm, 0, 0): the light
// (mesh.towardsLight) the vertex mirrors towards it. Nothing on a mesh without normals.
void addHighlights(Mesh& mesh, double eyeCentreXMm, IceKind ice, double gloss);

}  // namespace icewatch::synth
