// Z-buffer rasteriser for the synthetic scenes: projects every triangle with the ideal pinhole of
// one eye and keeps, per sample, the nearest surface and its perspective-correct attributes.
// Interpolating a/Z and 1/Z linearly in the image is what makes large triangles (the ground plate,
// the block's faces) carry their texture without distortion.
#include "core/synth/rasterizer.hpp"

#include <algorithm>
#include <cmath>

namespace icewatch::synth {

SampleBuffer rasterize(const std::vector<Mesh>& meshes, const PinholeView& view) {
    SampleBuffer buffer;
    buffer.inverseDepth = cv::Mat::zeros(view.size, CV_32F);
    buffer.material = cv::Mat(view.size, CV_32S, cv::Scalar(-1));
    buffer.attributes = cv::Mat::zeros(view.size, CV_32FC(VertexAttributes::channels));
    const int width = view.size.width, height = view.size.height;

    std::vector<cv::Vec3d> projected;
    for (const Mesh& mesh : meshes) {
        projected.resize(mesh.vertices.size());
        for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
            const cv::Vec3d& p = mesh.vertices[i];
            const double invZ = p[2] > 1e-6 ? 1.0 / p[2] : 0.0;
            projected[i] = {view.fPx * (p[0] - view.centreXMm) * invZ + view.cxPx, view.fPx * p[1] * invZ + view.cyPx,
                            invZ};
        }
        for (const auto& tri : mesh.triangles) {
            const cv::Vec3d& p0 = projected[static_cast<std::size_t>(tri[0])];
            const cv::Vec3d& p1 = projected[static_cast<std::size_t>(tri[1])];
            const cv::Vec3d& p2 = projected[static_cast<std::size_t>(tri[2])];
            if (p0[2] <= 0 || p1[2] <= 0 || p2[2] <= 0) {
                continue;  // behind the camera: the scenes never need clipping
            }
            const double area = (p1[0] - p0[0]) * (p2[1] - p0[1]) - (p2[0] - p0[0]) * (p1[1] - p0[1]);
            if (std::abs(area) < 1e-12) {
                continue;
            }
            const int x0 = std::max(0, static_cast<int>(std::ceil(std::min({p0[0], p1[0], p2[0]}))));
            const int x1 = std::min(width - 1, static_cast<int>(std::floor(std::max({p0[0], p1[0], p2[0]}))));
            const int y0 = std::max(0, static_cast<int>(std::ceil(std::min({p0[1], p1[1], p2[1]}))));
            const int y1 = std::min(height - 1, static_cast<int>(std::floor(std::max({p0[1], p1[1], p2[1]}))));
            const VertexAttributes& a0 = mesh.attributes[static_cast<std::size_t>(tri[0])];
            const VertexAttributes& a1 = mesh.attributes[static_cast<std::size_t>(tri[1])];
            const VertexAttributes& a2 = mesh.attributes[static_cast<std::size_t>(tri[2])];
            const double invArea = 1.0 / area;
            for (int y = y0; y <= y1; ++y) {
                auto* depthRow = buffer.inverseDepth.ptr<float>(y);
                auto* materialRow = buffer.material.ptr<int>(y);
                auto* attributeRow = buffer.attributes.ptr<VertexAttributes>(y);
                for (int x = x0; x <= x1; ++x) {
                    // Barycentric weights; a shared edge belongs to exactly one side (>= vs >).
                    const double w0 = ((p1[0] - x) * (p2[1] - y) - (p2[0] - x) * (p1[1] - y)) * invArea;
                    const double w1 = ((p2[0] - x) * (p0[1] - y) - (p0[0] - x) * (p2[1] - y)) * invArea;
                    const double w2 = 1.0 - w0 - w1;
                    if (w0 < 0 || w1 < 0 || w2 < 0) {
                        continue;
                    }
                    const double invZ = w0 * p0[2] + w1 * p1[2] + w2 * p2[2];
                    if (invZ <= depthRow[x]) {
                        continue;
                    }
                    depthRow[x] = static_cast<float>(invZ);
                    materialRow[x] = mesh.material;
                    const double k0 = w0 * p0[2] / invZ, k1 = w1 * p1[2] / invZ, k2 = w2 * p2[2] / invZ;
                    VertexAttributes value;
                    for (int c = 0; c < VertexAttributes::channels; ++c) {
                        value[c] = static_cast<float>(k0 * a0[c] + k1 * a1[c] + k2 * a2[c]);
                    }
                    attributeRow[x] = value;
                }
            }
        }
    }
    return buffer;
}

}  // namespace icewatch::synth
