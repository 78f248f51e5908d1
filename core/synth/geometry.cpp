// Geometry shared by the synthetic objects: poses, triangulated grids and flat faces.
#include "core/synth/geometry.hpp"

#include <cmath>

#include <opencv2/calib3d.hpp>

namespace icewatch::synth {

namespace {
constexpr double kPi = 3.14159265358979323846;
}

cv::Matx33d rotationFromDegrees(const cv::Vec3d& deg) {
    cv::Mat r;
    cv::Rodrigues(cv::Vec3d(deg[0], deg[1], deg[2]) * (kPi / 180.0), r);
    return cv::Matx33d(r);
}

std::vector<std::array<int, 3>> gridTriangles(int nu, int nv) {
    std::vector<std::array<int, 3>> triangles;
    triangles.reserve(static_cast<std::size_t>(nu) * nv * 2);
    for (int j = 0; j < nv; ++j) {
        for (int i = 0; i < nu; ++i) {
            const int a = j * (nu + 1) + i, b = a + 1, c = a + nu + 1, d = c + 1;
            triangles.push_back({a, b, d});
            triangles.push_back({a, d, c});
        }
    }
    return triangles;
}

double iceVolumeMm3(const GridSurface& s) {
    double volume = 0.0;
    for (const auto& t : gridTriangles(s.nu, s.nv)) {
        const cv::Vec3d& p0 = s.local[static_cast<std::size_t>(t[0])];
        const cv::Vec3d& p1 = s.local[static_cast<std::size_t>(t[1])];
        const cv::Vec3d& p2 = s.local[static_cast<std::size_t>(t[2])];
        const double area = 0.5 * std::abs((p1[0] - p0[0]) * (p2[1] - p0[1]) - (p2[0] - p0[0]) * (p1[1] - p0[1]));
        volume += area * (s.ice[static_cast<std::size_t>(t[0])] + s.ice[static_cast<std::size_t>(t[1])] +
                          s.ice[static_cast<std::size_t>(t[2])]) /
                  3.0;
    }
    return volume;
}

std::vector<cv::Vec3d> gridNormals(const GridSurface& s, const std::vector<cv::Vec3d>& camera) {
    std::vector<cv::Vec3d> normals(camera.size());
    for (int j = 0; j <= s.nv; ++j) {
        for (int i = 0; i <= s.nu; ++i) {
            const cv::Vec3d du = camera[s.index(std::min(i + 1, s.nu), j)] - camera[s.index(std::max(i - 1, 0), j)];
            const cv::Vec3d dv = camera[s.index(i, std::min(j + 1, s.nv))] - camera[s.index(i, std::max(j - 1, 0))];
            cv::Vec3d n = du.cross(dv);
            const double len = cv::norm(n);
            n = len > 0 ? n / len : cv::Vec3d(0, 0, -1);
            normals[s.index(i, j)] = n[2] > 0 ? -n : n;  // facing the camera
        }
    }
    return normals;
}

void addQuad(Mesh& mesh, const Pose& pose, const cv::Vec3d& origin, const cv::Vec3d& edgeU, const cv::Vec3d& edgeV,
             int divisions, const Look& look) {
    const int base = static_cast<int>(mesh.vertices.size());
    const cv::Vec3d a = pose.toCamera(origin[0], origin[1], origin[2]);
    const cv::Vec3d b = pose.toCamera(origin[0] + edgeU[0], origin[1] + edgeU[1], origin[2] + edgeU[2]);
    const cv::Vec3d c = pose.toCamera(origin[0] + edgeV[0], origin[1] + edgeV[1], origin[2] + edgeV[2]);
    cv::Vec3d n = (b - a).cross(c - a);
    n = cv::normalize(n);
    if (n[2] > 0) n = -n;
    const float shade = lambert(look, n);
    mesh.towardsLight = look.towardsLight;
    for (int j = 0; j <= divisions; ++j) {
        for (int i = 0; i <= divisions; ++i) {
            const double fu = static_cast<double>(i) / divisions, fv = static_cast<double>(j) / divisions;
            const cv::Vec3d local = origin + fu * edgeU + fv * edgeV;
            mesh.vertices.push_back(pose.toCamera(local[0], local[1], local[2]));
            const double ta = std::abs(edgeU[0]) + std::abs(edgeV[0]) > 0 ? local[0] : local[1];
            const double tb = std::abs(edgeU[1]) + std::abs(edgeV[1]) > 0 && ta != local[1] ? local[1] : local[2];
            const float height = mesh.material == kMaterialIceBlock ? static_cast<float>(local[2]) : 0.0f;
            const auto u = static_cast<float>(ta), v = static_cast<float>(tb);
            mesh.attributes.push_back({u, v, shade, height, u, v, 0.0f});
            mesh.normals.push_back(n);
        }
    }
    for (const auto& t : gridTriangles(divisions, divisions)) {
        mesh.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
    }
}

}  // namespace icewatch::synth
