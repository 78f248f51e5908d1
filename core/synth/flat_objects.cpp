// The flat things of the synthetic scenes: the seed paper's plate with its ice block, and the
// tabletop a blade or a plate can lie on.
#include "core/synth/flat_objects.hpp"

namespace icewatch::synth {

namespace {
// The view spans about ±0.72 m × ±0.41 m at 0.85 m; the table reaches well beyond in every direction.
constexpr double kTableLengthMm = 2600.0;
constexpr double kTableWidthMm = 1800.0;
}  // namespace

std::vector<Mesh> blockMeshes(double blockHeightMm, bool onTable, const Pose& pose, const Look& look) {
    Mesh plate;
    plate.material = kMaterialPlate;
    const double px = kPlateLengthMm / 2, py = kPlateWidthMm / 2;
    addQuad(plate, pose, {-px, -py, 0}, {kPlateLengthMm, 0, 0}, {0, kPlateWidthMm, 0}, 16, look);
    if (onTable) {
        const double t = kPlateThicknessMm;
        addQuad(plate, pose, {-px, -py, -t}, {kPlateLengthMm, 0, 0}, {0, 0, t}, 4, look);
        addQuad(plate, pose, {-px, py, -t}, {kPlateLengthMm, 0, 0}, {0, 0, t}, 4, look);
        addQuad(plate, pose, {-px, -py, -t}, {0, kPlateWidthMm, 0}, {0, 0, t}, 4, look);
        addQuad(plate, pose, {px, -py, -t}, {0, kPlateWidthMm, 0}, {0, 0, t}, 4, look);
    }
    std::vector<Mesh> meshes{plate};
    if (blockHeightMm > 0) {
        Mesh block;
        block.material = kMaterialIceBlock;
        const double x0 = -kBlockLengthMm / 2 + 15.0, y0 = -kBlockWidthMm / 2 - 10.0;
        const double x1 = x0 + kBlockLengthMm, y1 = y0 + kBlockWidthMm, h = blockHeightMm;
        addQuad(block, pose, {x0, y0, h}, {kBlockLengthMm, 0, 0}, {0, kBlockWidthMm, 0}, 8, look);
        addQuad(block, pose, {x0, y0, 0}, {kBlockLengthMm, 0, 0}, {0, 0, h}, 8, look);
        addQuad(block, pose, {x0, y1, 0}, {kBlockLengthMm, 0, 0}, {0, 0, h}, 8, look);
        addQuad(block, pose, {x0, y0, 0}, {0, kBlockWidthMm, 0}, {0, 0, h}, 8, look);
        addQuad(block, pose, {x1, y0, 0}, {0, kBlockWidthMm, 0}, {0, 0, h}, 8, look);
        meshes.push_back(block);
    }
    return meshes;
}

Mesh tableMesh(double heightMm, const Pose& pose, const Look& look) {
    Mesh table;
    table.material = kMaterialTable;
    addQuad(table, pose, {-kTableLengthMm / 2, -kTableWidthMm / 2, heightMm}, {kTableLengthMm, 0, 0},
            {0, kTableWidthMm, 0}, 24, look);
    return table;
}

}  // namespace icewatch::synth
