#pragma once

#include <cstdint>

#include <opencv2/core.hpp>

namespace icewatch::synth {

// How a scene looks, drawn from its seed within plausible ranges, so that a chain tuned on one
// picture meets other light, other textures and other ice on the next seed.
struct Look {
    cv::Vec3d towardsLight = cv::normalize(cv::Vec3d(-0.3, -0.5, -1.0));  // unit, left camera frame
    double ambient = 0.55;  // the share of the light that reaches every surface alike
    double diffuse = 0.45;  // the share that falls as the normal faces the light (1 - ambient)
    double compositeAlbedo = 0.62;
    double compositeContrast = 0.035;  // amplitude of the composite's weak texture
    double compositeFeatureMm = 6.0;   // size of its coarsest features
    double iceWhiteness = 0.88;        // albedo of ice thick enough to hide what is under it
    double iceTranslucencyMm = 1.5;    // thickness of ice that hides 63 % of what is under it
    double tableGrainDeg = 0.0;        // direction of the tabletop's grain in the object plane
    // A glaze so clear that the composite's texture keeps its contrast under it, brightened by a
    // gain as a change of light would brighten it (the layer reflects more): only its background
    // tells it from light. Otherwise the glaze veils the texture (whiter, of lower contrast).
    bool glazeKeepsTexture = false;
    // The peak of the light that wet ice mirrors towards the eye (highlight.hpp); the blade's coat
    // mirrors less, rime nothing. 0: every surface matte.
    double gloss = 0.0;
};

// With fixedLight the light keeps its default (a lab rig under fixed lamps); the rest still varies.
Look drawLook(std::uint32_t seed, bool fixedLight = false);

// Lambert shading of a surface with this unit normal (facing the camera) under the look's light.
float lambert(const Look& look, const cv::Vec3d& normal);

}  // namespace icewatch::synth
