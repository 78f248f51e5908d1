// The seed's look: light, the composite's texture and the ice's whiteness vary from seed to seed
// within what an outdoor camera on a parked turbine sees, around the values of the first scenes
// (light from the upper left, a weak composite texture of ~6 mm features, white ice translucent
// over ~1.5 mm). Drawn from a stream of its own, so that poses, motions and noise stay what the
// seed gave before the look varied.
#include "core/synth/look.hpp"

#include <algorithm>
#include <random>

namespace icewatch::synth {

Look drawLook(std::uint32_t seed, bool fixedLight) {
    std::mt19937 random(seed ^ 0x4c6f6f6bu);
    auto uniform = [&random](double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(random); };
    Look look;
    const cv::Vec3d towardsLight = cv::normalize(cv::Vec3d(uniform(-0.6, 0.3), uniform(-0.75, -0.25), -1.0));
    const double ambient = uniform(0.45, 0.65);
    if (!fixedLight) {
        look.towardsLight = towardsLight;
        look.ambient = ambient;
        look.diffuse = 1.0 - ambient;
    }
    look.compositeAlbedo = uniform(0.56, 0.68);
    look.compositeContrast = uniform(0.027, 0.05);
    look.compositeFeatureMm = uniform(4.5, 8.5);
    look.iceWhiteness = uniform(0.82, 0.93);
    look.iceTranslucencyMm = uniform(0.8, 2.5);
    // Grain across the epipolar lines as often as along them: anywhere but near-horizontal, where a
    // wood grain would hide the horizontal disparity (real tables vary; the chain should not be
    // tested on that degenerate case by accident).
    look.tableGrainDeg = uniform(20.0, 70.0) * (random() % 2 == 0 ? 1.0 : -1.0);
    // Every other seed, so that any two seeds in a row show both glazes.
    look.glazeKeepsTexture = seed % 2 == 0;
    return look;
}

float lambert(const Look& look, const cv::Vec3d& normal) {
    return static_cast<float>(look.ambient + look.diffuse * std::max(0.0, normal.dot(look.towardsLight)));
}

}  // namespace icewatch::synth
