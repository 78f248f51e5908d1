#pragma once

namespace icewatch {

// Ice's refractive index (visible light, near 0 °C): what the renderer bends its rays by and what
// the volume chain allows for where it saw the blade through ice.
inline constexpr double kIceRefractiveIndex = 1.31;

}  // namespace icewatch
