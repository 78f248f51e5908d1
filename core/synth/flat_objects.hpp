#pragma once

#include <vector>

#include "core/synth/geometry.hpp"

namespace icewatch::synth {

// Table 5's block: a fixed footprint, the height makes the volume.
inline constexpr double kBlockLengthMm = 100.0;
inline constexpr double kBlockWidthMm = 80.0;
inline constexpr double kPlateLengthMm = 420.0;
inline constexpr double kPlateWidthMm = 320.0;
inline constexpr double kPlateThicknessMm = 15.0;  // shown only when the plate lies on a table

// The plate (object plane h = 0, centred on the origin) and, for a height above 0, the ice block on
// it. With onTable the plate gets the thickness and edges of a real board, so it can lie on a table.
std::vector<Mesh> blockMeshes(double blockHeightMm, bool onTable, const Pose& pose, const Look& look);

// A tabletop filling the view around the object: the plane h = heightMm, far larger than the
// camera's field of view at the object's distance.
Mesh tableMesh(double heightMm, const Pose& pose, const Look& look);

}  // namespace icewatch::synth
