// Shading of the synthetic scenes: procedural textures fixed to each surface (texture.hpp), so a
// surface point has the same grey in both eyes and both captures (stereo and registration need
// exactly that), lit by the look's light. Every texture is a pure function of the surface
// coordinates and the seed.
#include "core/synth/shading.hpp"

#include <cmath>

#include "core/synth/geometry.hpp"
#include "core/synth/texture.hpp"

namespace icewatch::synth {

namespace {

constexpr double kPi = 3.14159265358979323846;

// Composite: a weak, smooth texture (the hard case for a matcher).
float composite(const Shading& s, float a, float b) {
    const Look& look = s.look;
    const double coarse = fractalNoise(a, b, look.compositeFeatureMm, 4, s.seed);
    const double fine = fractalNoise(a, b, 0.2 * look.compositeFeatureMm, 2, s.seed + 7);
    return static_cast<float>(look.compositeAlbedo + look.compositeContrast * (coarse + 0.43 * fine));
}

// Rime is opaque from a fraction of a millimetre.
float rimeOpacity(float thicknessMm) { return 1.0f - std::exp(-thicknessMm / 0.3f); }

// What a glaze of this thickness does to what is seen through it (the composite's albedo, or the
// light of what lies behind an edge it wraps): a glaze so clear that the texture keeps its contrast
// brightens it as light would; otherwise it whitens it and lowers its contrast the thicker the
// layer, with a faint texture of the glaze's own surface, that white under the light `lit` (1 for
// an albedo, lit afterwards).
float throughGlaze(const Shading& s, float seen, float thickness, float lit, const VertexAttributes& a) {
    const auto translucencyMm = static_cast<float>(s.look.iceTranslucencyMm);
    if (s.look.glazeKeepsTexture) return seen * (1.0f + 0.15f * (1.0f - std::exp(-thickness / translucencyMm)));
    const float veil = 0.1f + 0.35f * (1.0f - std::exp(-thickness / (2.0f * translucencyMm)));
    const auto whiteness = static_cast<float>(s.look.iceWhiteness);
    const float glaze = (whiteness + 0.015f * fractalNoise(a[0], a[1], 2.0, 3, s.seed + 110)) * lit;
    return seen + (glaze - seen) * veil;
}

// What the blade's ice does to the composite under it.
float icedComposite(const Shading& s, float albedo, const VertexAttributes& a) {
    const float thickness = a[3];
    const auto whiteness = static_cast<float>(s.look.iceWhiteness);
    const auto translucencyMm = static_cast<float>(s.look.iceTranslucencyMm);
    switch (s.ice) {
        case IceKind::LeadingEdge:
        case IceKind::Bead:
        case IceKind::BeadGlaze:
        case IceKind::Ridges:
        case IceKind::Shed:
        case IceKind::Icicles: {
            // White, translucent where thin, with its own faint texture.
            const float opacity = 1.0f - std::exp(-thickness / translucencyMm);
            const float ice = whiteness + 0.03f * fractalNoise(a[0], a[1], 3.0, 3, s.seed + 100);
            return albedo + (ice - albedo) * opacity;
        }
        case IceKind::GlazeAll:
            return throughGlaze(s, albedo, thickness, 1.0f, a);
        case IceKind::Patches: {
            // Rime: opaque white from a fraction of a millimetre, rough, with a texture of its own.
            const float opacity = rimeOpacity(thickness);
            const float rime = whiteness + 0.06f * fractalNoise(a[0], a[1], 2.5, 4, s.seed + 150);
            return albedo + (rime - albedo) * opacity;
        }
    }
    return albedo;
}

// A wooden tabletop: growth rings across the grain, warped, with fibres along it, blotches and
// pores; far more texture than the composite, as a real table has.
float tabletop(const Shading& s, float a, float b) {
    const double angle = s.look.tableGrainDeg * kPi / 180.0;
    const double along = a * std::cos(angle) + b * std::sin(angle), across = -a * std::sin(angle) + b * std::cos(angle);
    // Few octaves: the table fills the whole frame, so its texture is the renderer's hottest loop.
    const double wave = across + 10.0 * fractalNoise(along, across, 120.0, 2, s.seed + 400);
    const double rings = std::sin(2.0 * kPi * wave / 12.0);
    const double fibres = fractalNoise(along / 6.0, across, 1.2, 2, s.seed + 410);
    const double blotches = fractalNoise(along, across, 30.0, 2, s.seed + 420);
    const double pores = fractalNoise(along, across, 2.0, 1, s.seed + 430);
    return static_cast<float>(0.42 + 0.045 * rings + 0.05 * fibres + 0.05 * blotches + 0.03 * pores);
}

// What a surface scatters: its texture under the light it was shaded with.
float diffuseLight(const Shading& shading, int material, const VertexAttributes& a) {
    switch (material) {
        case kMaterialBlade: {
            // The composite where the eye sees it: under the ice, when the ice is clear enough to show it.
            const float albedo = composite(shading, a[kAttributeSeenA], a[kAttributeSeenB]);
            if (a[3] <= 0.0f) return albedo * a[2];
            if (shading.ice == IceKind::Patches) {
                // Rime scatters light inside itself, so its shading is flatter than Lambert's.
                const float opacity = rimeOpacity(a[3]);
                return icedComposite(shading, albedo, a) * (a[2] + (1.0f - a[2]) * 0.5f * opacity);
            }
            return icedComposite(shading, albedo, a) * a[2];
        }
        case kMaterialBeadFront:
            // Ice with nothing under it but sky: its own white, with its own faint texture.
            return (static_cast<float>(shading.look.iceWhiteness) +
                    0.03f * fractalNoise(a[0], a[1], 3.0, 3, shading.seed + 100)) * a[2];
        case kMaterialIceBlock:
            return (0.86f + 0.04f * fractalNoise(a[0], a[1], 4.0, 4, shading.seed + 200)) * a[2];
        case kMaterialPlate:
            return (0.45f + 0.12f * fractalNoise(a[0], a[1], 8.0, 5, shading.seed + 300)) * a[2];
        case kMaterialTable:
            return tabletop(shading, a[0], a[1]) * a[2];
        default:
            return 0.0f;
    }
}

float sky(const Shading& shading, float skyX, float skyY) {
    // Overcast sky: bright, almost featureless; clouds, as far as the sky, lie at the same
    // place in both eyes and drift between the captures.
    const float overcast = 0.80f + 0.05f * skyY;
    if (shading.cloudContrast <= 0) return overcast;
    return overcast + static_cast<float>(shading.cloudContrast) *
                          fractalNoise(skyX + shading.cloudShift, skyY, 0.2, 3, shading.seed + 400);
}

// A glaze wrapping the blade's edge, out of its outline: nothing of the blade under it, so what
// lies behind shows through it (the table's texture there, lit as the glaze's plane; or the sky).
float glazeEdgeLight(const Shading& s, const VertexAttributes& a, float skyBehind) {
    const float behind = s.background == Background::Table ? tabletop(s, a[0], a[1]) * a[kAttributeShade] : skyBehind;
    return throughGlaze(s, behind, a[kAttributeExtra], a[kAttributeShade], a);
}

}  // namespace

float shadeSample(const Shading& shading, int material, const VertexAttributes& a, float skyX, float skyY) {
    if (material < 0) return sky(shading, skyX, skyY);
    if (material == kMaterialGlazeEdge) {
        return glazeEdgeLight(shading, a, sky(shading, skyX, skyY)) + a[kAttributeHighlight];
    }
    // What the surface scatters, and on top of it what it mirrors towards this eye (highlight.hpp).
    return diffuseLight(shading, material, a) + a[kAttributeHighlight];
}

}  // namespace icewatch::synth
