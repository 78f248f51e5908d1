#pragma once

#include "core/common/ice.hpp"
#include "core/synth/rasterizer.hpp"

namespace icewatch::synth {

// The mesh as the eye at (eyeCentreXMm, 0, 0) sees it: where the mesh carries a clear layer, each
// vertex's seen coordinates (kAttributeSeenA/B) become those of the point under the layer that the
// eye's ray reaches after Snell's law bends it at the layer's surface. A stereo camera then sees that
// surface raised by about (1 − 1/n) of the layer's thickness, not by all of it: a clear glaze shows
// the texture under it nearly where it was. A mesh without a clear layer is returned as it is.
Mesh seenThroughClearLayer(const Mesh& mesh, double eyeCentreXMm);

}  // namespace icewatch::synth
