#pragma once

#include <array>
#include <vector>

#include <opencv2/core.hpp>

#include "core/synth/look.hpp"
#include "core/synth/rasterizer.hpp"

namespace icewatch::synth {

// What a rendered sample is made of; the shading stage picks the texture by it.
enum Material : int {
    kMaterialBlade = 0,
    kMaterialIceBlock = 1,
    kMaterialPlate = 2,
    kMaterialTable = 3,
    kMaterialBeadFront = 4,  // ice standing in front of the blade's leading edge: no blade under it
    kMaterialGlazeEdge = 5,  // a glaze wrapping the blade's edges, out of its outline: clear, nothing under it
};

// An object frame (x, y in the object's plane, h its height towards the camera) placed in the left
// camera frame.
struct Pose {
    cv::Matx33d rotation;
    cv::Vec3d translation;
    cv::Vec3d toCamera(double x, double y, double h) const { return rotation * cv::Vec3d(x, y, -h) + translation; }
};

cv::Matx33d rotationFromDegrees(const cv::Vec3d& deg);

// A surface sampled on a (nu+1) × (nv+1) grid in its object frame, triangulated two per cell.
struct GridSurface {
    int nu = 0, nv = 0;
    std::vector<cv::Vec3d> local;  // x, y, h
    std::vector<float> ice;        // ice thickness carried at each vertex, mm
    std::size_t index(int i, int j) const { return static_cast<std::size_t>(j) * (nu + 1) + i; }
};

std::vector<std::array<int, 3>> gridTriangles(int nu, int nv);

// Ice volume of a grid surface: planform area of each triangle (in the object's x-y plane) times
// its mean vertex thickness. Exact for the piecewise-linear surface that is rendered.
double iceVolumeMm3(const GridSurface& s);

// Per-vertex unit normals of the posed surface, facing the camera.
std::vector<cv::Vec3d> gridNormals(const GridSurface& s, const std::vector<cv::Vec3d>& camera);

// A flat rectangle origin + u·edgeU + v·edgeV (object frame, mm), subdivided so that no triangle
// is huge, appended to mesh and shaded flat under the look's light. The texture coordinates are
// the two object coordinates that vary on the face; the extra attribute is the height above the
// object plane for an ice block's faces (its thickness), 0 for anything else.
void addQuad(Mesh& mesh, const Pose& pose, const cv::Vec3d& origin, const cv::Vec3d& edgeU, const cv::Vec3d& edgeV,
             int divisions, const Look& look);

}  // namespace icewatch::synth
