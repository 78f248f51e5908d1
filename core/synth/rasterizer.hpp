#pragma once

#include <array>
#include <vector>

#include <opencv2/core.hpp>

namespace icewatch::synth {

// A triangle mesh in camera coordinates (mm, left camera frame, +Z forward). Each vertex carries
// four attributes interpolated perspective-correctly over the triangles: the surface coordinates
// a and b (texture lookup), a Lambert shading factor and a material-specific extra (ice thickness).
struct Mesh {
    int material = 0;
    std::vector<cv::Vec3d> vertices;
    std::vector<cv::Vec4f> attributes;
    std::vector<std::array<int, 3>> triangles;
};

// The visible surface at every sample of a (supersampled) image: the nearest triangle wins.
struct SampleBuffer {
    cv::Mat inverseDepth;  // CV_32F, 1/Z, 0 where no mesh covers the sample
    cv::Mat material;      // CV_32S, -1 where empty
    cv::Mat attributes;    // CV_32FC4
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
