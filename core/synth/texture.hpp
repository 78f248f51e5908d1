#pragma once

#include <cstdint>

namespace icewatch::synth {

// Smooth value noise in [-1, 1] on a lattice of unit spacing, deterministic per seed.
float valueNoise(double x, double y, std::uint32_t seed);

// Fractal sum of value noise: octaves from featureMm down by halves, amplitudes by halves,
// normalised to about [-1, 1]. Coordinates are surface millimetres, so a texture moves with its
// object.
float fractalNoise(double xMm, double yMm, double featureMm, int octaves, std::uint32_t seed);

}  // namespace icewatch::synth
