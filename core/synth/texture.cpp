// Procedural textures for the synthetic scenes: hashed value noise, so every surface point has a
// fixed grey value whatever the pose or resolution it is seen at (stereo needs exactly that).
#include "core/synth/texture.hpp"

#include <cmath>

namespace icewatch::synth {

namespace {

float latticeValue(std::int64_t ix, std::int64_t iy, std::uint32_t seed) {
    // A small integer hash (lowbias32-style mixing); quality is ample for a texture.
    auto h = static_cast<std::uint32_t>(ix * 0x27d4eb2dLL) ^ static_cast<std::uint32_t>(iy * 0x165667b1LL) ^
             (seed * 0x9e3779b9u);
    h ^= h >> 16;
    h *= 0x7feb352du;
    h ^= h >> 15;
    h *= 0x846ca68bu;
    h ^= h >> 16;
    return static_cast<float>(h) * (2.0f / 4294967295.0f) - 1.0f;
}

float smooth(float t) { return t * t * (3.0f - 2.0f * t); }

}  // namespace

float valueNoise(double x, double y, std::uint32_t seed) {
    const double fx = std::floor(x), fy = std::floor(y);
    const auto ix = static_cast<std::int64_t>(fx), iy = static_cast<std::int64_t>(fy);
    const float tx = smooth(static_cast<float>(x - fx)), ty = smooth(static_cast<float>(y - fy));
    const float v00 = latticeValue(ix, iy, seed), v10 = latticeValue(ix + 1, iy, seed);
    const float v01 = latticeValue(ix, iy + 1, seed), v11 = latticeValue(ix + 1, iy + 1, seed);
    const float top = v00 + (v10 - v00) * tx;
    const float bottom = v01 + (v11 - v01) * tx;
    return top + (bottom - top) * ty;
}

float fractalNoise(double xMm, double yMm, double featureMm, int octaves, std::uint32_t seed) {
    float sum = 0.0f, norm = 0.0f, amplitude = 1.0f;
    double scale = 1.0 / featureMm;
    for (int o = 0; o < octaves; ++o) {
        sum += amplitude * valueNoise(xMm * scale + 17.3 * o, yMm * scale - 5.1 * o, seed + static_cast<std::uint32_t>(o));
        norm += amplitude;
        amplitude *= 0.5f;
        scale *= 2.0;
    }
    return sum / norm;
}

}  // namespace icewatch::synth
