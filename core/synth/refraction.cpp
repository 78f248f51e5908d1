// What an eye sees under clear ice: the ray from the eye to a point of the layer's surface is bent
// towards the normal as it enters the ice (Snell: sin θ = n · sin θ'), and the eye sees the surface
// under the layer where the bent ray meets it. Worked per vertex and interpolated over the
// triangles: the bend changes slowly over a triangle, the texture it looks up does not.
#include "core/synth/refraction.hpp"

#include <algorithm>
#include <cmath>

namespace icewatch::synth {

namespace {

// Snell's law for a unit ray `d` meeting a surface of unit normal `n` (facing the ray) from air.
cv::Vec3d refractIntoIce(const cv::Vec3d& d, const cv::Vec3d& n) {
    const double eta = 1.0 / kIceRefractiveIndex;
    const double cosIn = -n.dot(d);
    const double cosOut = std::sqrt(std::max(0.0, 1.0 - eta * eta * (1.0 - cosIn * cosIn)));
    return eta * d + (eta * cosIn - cosOut) * n;
}

}  // namespace

Mesh seenThroughClearLayer(const Mesh& mesh, double eyeCentreXMm) {
    if (!mesh.clearLayer) return mesh;
    const ClearLayer& layer = *mesh.clearLayer;
    Mesh seen = mesh;
    const cv::Vec3d eye(eyeCentreXMm, 0.0, 0.0);
    for (std::size_t k = 0; k < mesh.vertices.size(); ++k) {
        VertexAttributes& a = seen.attributes[k];
        if (a[kAttributeExtra] <= 0.0f) continue;  // no layer over this vertex
        const cv::Vec3d& p = mesh.vertices[k];
        const cv::Vec3d ray = cv::normalize(p - eye);
        cv::Vec3d normal = layer.normal[k];
        if (normal.dot(ray) > 0) normal = -normal;  // the side this eye looks at
        const cv::Vec3d bent = refractIntoIce(ray, normal);
        // Where the bent ray meets the tangent plane of the surface under the layer.
        const cv::Vec3d& underNormal = layer.underNormal[k];
        const double along = bent.dot(underNormal);
        const double reach = std::abs(along) > 1e-6 ? (layer.under[k] - p).dot(underNormal) / along : 0.0;
        const cv::Vec3d hit = p + std::max(0.0, reach) * bent;
        const cv::Vec2d coordinates = layer.textureAxes * (hit - layer.textureOrigin);
        a[kAttributeSeenA] = static_cast<float>(coordinates[0]);
        a[kAttributeSeenB] = static_cast<float>(coordinates[1]);
    }
    return seen;
}

}  // namespace icewatch::synth
