#pragma once

#include <cstdint>

#include <opencv2/core.hpp>

#include "core/synth/look.hpp"
#include "core/synth/rasterizer.hpp"
#include "core/synth/scene.hpp"
#include "core/synth/shadow.hpp"

namespace icewatch::synth {

// Everything the shading of a sample depends on besides the sample itself.
struct Shading {
    Look look;
    IceKind ice = IceKind::LeadingEdge;
    std::uint32_t seed = 1;
    // Clouds in the sky (0: an even overcast): their contrast, and how far they drifted, as a share
    // of the image's width, since the baseline.
    double cloudContrast = 0;
    double cloudShift = 0;
    // Cast shadows of the capture's light (shadow.hpp); none: every surface sees the light.
    const ShadowMap* shadows = nullptr;
    // What lies behind the object: what shows through ice that stands out of it (kMaterialGlazeEdge).
    Background background = Background::Sky;
};

// Light (0..1, before the camera's gain) of one sample from its material and its attributes
// (rasterizer.hpp: surface coordinates a, b in mm, Lambert factor, ice thickness in mm, and where
// the surface under the ice is seen); material < 0 is the sky,
// (skyX, skyY) its place in the image (0 .. 1 from the left, 0 bottom .. 1 top).
float shadeSample(const Shading& shading, int material, const VertexAttributes& a, float skyX, float skyY);

}  // namespace icewatch::synth
