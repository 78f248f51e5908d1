// Highlights of glossy surfaces, per eye and per vertex, interpolated over the triangles as the
// refraction is: the meshes are fine enough (a few pixels a triangle) for highlights as broad as
// these exponents make them.
#include "core/synth/highlight.hpp"

#include <algorithm>
#include <cmath>

#include "core/synth/geometry.hpp"

namespace icewatch::synth {

namespace {

constexpr Gloss kIceGloss{1.0, 80.0};      // wet, smooth ice: a small, bright highlight
constexpr Gloss kCoatGloss{0.35, 20.0};    // the blade's gelcoat: a broad, faint sheen
constexpr double kGlossyIceMm = 0.3;       // ice this thick covers the coat's sheen by 63 %

}  // namespace

Gloss surfaceGloss(int material, IceKind ice, double thicknessMm, double gloss) {
    const bool rime = ice == IceKind::Patches;  // rough and opaque: it scatters, it does not mirror
    switch (material) {
        case kMaterialBlade: {
            const double cover = 1.0 - std::exp(-std::max(0.0, thicknessMm) / kGlossyIceMm);
            const double strength = rime ? kCoatGloss.strength * (1.0 - cover)
                                         : kCoatGloss.strength + (kIceGloss.strength - kCoatGloss.strength) * cover;
            const double exponent = rime ? kCoatGloss.exponent
                                         : kCoatGloss.exponent + (kIceGloss.exponent - kCoatGloss.exponent) * cover;
            return {gloss * strength, exponent};
        }
        case kMaterialBeadFront:
        case kMaterialIceBlock:
            return {gloss * kIceGloss.strength, kIceGloss.exponent};
        default:
            return {};
    }
}

void addHighlights(Mesh& mesh, double eyeCentreXMm, IceKind ice, double gloss) {
    if (mesh.normals.size() != mesh.vertices.size()) return;
    const cv::Vec3d eye(eyeCentreXMm, 0.0, 0.0);
    for (std::size_t k = 0; k < mesh.vertices.size(); ++k) {
        VertexAttributes& a = mesh.attributes[k];
        const Gloss g = surfaceGloss(mesh.material, ice, a[kAttributeExtra], gloss);
        if (g.strength <= 0) {
            a[kAttributeHighlight] = 0.0f;
            continue;
        }
        const cv::Vec3d towardsEye = cv::normalize(eye - mesh.vertices[k]);
        const cv::Vec3d halfway = cv::normalize(towardsEye + mesh.towardsLight);
        const double facing = std::max(0.0, mesh.normals[k].dot(halfway));
        a[kAttributeHighlight] = static_cast<float>(g.strength * std::pow(facing, g.exponent));
    }
}

}  // namespace icewatch::synth
