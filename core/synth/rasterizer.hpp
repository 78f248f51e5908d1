#pragma once

#include <array>
#include <optional>
#include <vector>

#include <opencv2/core.hpp>

namespace icewatch::synth {

// What each vertex carries, interpolated perspective-correctly over the triangles: the surface
// coordinates a and b (texture lookup), a Lambert shading factor, a material-specific extra (ice
// thickness), the surface coordinates of what the eye sees under a clear layer at this vertex
// (a and b again where there is no layer, or where the layer is painted on: refraction.hpp), and
// the light a glossy surface mirrors towards the eye (highlight.hpp; 0 on a matte one).
using VertexAttributes = cv::Vec<float, 7>;
inline constexpr int kAttributeA = 0, kAttributeB = 1, kAttributeShade = 2, kAttributeExtra = 3, kAttributeSeenA = 4,
                     kAttributeSeenB = 5, kAttributeHighlight = 6;

// A clear layer over the surface (ice) for the eyes to see through: per vertex, the point of the
// surface under the layer, that surface's normal and the layer's own outer normal (camera frame);
// the surface coordinates of a point p under the layer are textureAxes · (p − textureOrigin).
struct ClearLayer {
    std::vector<cv::Vec3d> under;
    std::vector<cv::Vec3d> underNormal;
    std::vector<cv::Vec3d> normal;
    cv::Matx23d textureAxes;
    cv::Vec3d textureOrigin;
};

// A triangle mesh in camera coordinates (mm, left camera frame, +Z forward).
struct Mesh {
    int material = 0;
    std::vector<cv::Vec3d> vertices;
    std::vector<VertexAttributes> attributes;
    std::vector<std::array<int, 3>> triangles;
    std::optional<ClearLayer> clearLayer;  // none: opaque, or its layer painted on its surface
    // For highlights (highlight.hpp): per vertex, the unit normal facing the camera, and the light
    // the mesh was shaded under. Empty normals: the mesh has no highlights.
    std::vector<cv::Vec3d> normals;
    cv::Vec3d towardsLight;
};

// The visible surface at every sample of a (supersampled) image: the nearest triangle wins.
struct SampleBuffer {
    cv::Mat inverseDepth;  // CV_32F, 1/Z, 0 where no mesh covers the sample
    cv::Mat material;      // CV_32S, -1 where empty
    cv::Mat attributes;    // CV_32FC(7), VertexAttributes
};

// A pinhole camera at (centreXMm, 0, 0) looking along +Z with focal fPx and principal point
// (cxPx, cyPx) in the coordinates of the buffer it renders into.
struct PinholeView {
    double fPx = 0;
    double cxPx = 0;
    double cyPx = 0;
    double centreXMm = 0;
    cv::Size size;
};

// Z-buffer rasterisation of the meshes; sample centres at integer coordinates.
SampleBuffer rasterize(const std::vector<Mesh>& meshes, const PinholeView& view);

}  // namespace icewatch::synth
