// Cast shadows for the synthetic scenes: the casters are rasterised once per capture into a depth
// map looking along the light (orthographic, since the sun is a directional light), and every
// rendered sample asks it whether something nearer to the light covers it.
#include "core/synth/shadow.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace icewatch::synth {

namespace {

// The map never grows past this many cells a side: a caster larger than that gets coarser cells.
constexpr int kMaxCells = 6000;
// A surface is in its own light up to this far behind the map's depth (mm): the bilinear map
// follows a smooth caster's own surface far closer than that, and no shadow the scenes cast is
// this shallow.
constexpr double kSelfBiasMm = 0.3;

}  // namespace

ShadowMap::ShadowMap(const std::vector<Mesh>& casters, const cv::Vec3d& towardsLight, double cellMm)
    : cellMm_(cellMm) {
    w_ = -cv::normalize(towardsLight);
    // Any two axes across the light; the one least aligned with it keeps them well conditioned.
    const cv::Vec3d helper = std::abs(w_[0]) < 0.9 ? cv::Vec3d(1, 0, 0) : cv::Vec3d(0, 1, 0);
    u_ = cv::normalize(helper.cross(w_));
    v_ = w_.cross(u_);

    double minU = std::numeric_limits<double>::infinity(), minV = minU, maxU = -minU, maxV = -minU;
    for (const Mesh& mesh : casters) {
        for (const cv::Vec3d& p : mesh.vertices) {
            minU = std::min(minU, u_.dot(p));
            maxU = std::max(maxU, u_.dot(p));
            minV = std::min(minV, v_.dot(p));
            maxV = std::max(maxV, v_.dot(p));
        }
    }
    if (!(maxU >= minU)) {  // nothing casts a shadow
        depth_ = cv::Mat(1, 1, CV_32F, cv::Scalar(std::numeric_limits<float>::infinity()));
        origin_ = {0, 0};
        return;
    }
    cellMm_ = std::max(cellMm_, std::max(maxU - minU, maxV - minV) / (kMaxCells - 4));
    origin_ = {minU - cellMm_, minV - cellMm_};
    const int width = static_cast<int>(std::ceil((maxU - minU) / cellMm_)) + 3;
    const int height = static_cast<int>(std::ceil((maxV - minV) / cellMm_)) + 3;
    depth_ = cv::Mat(height, width, CV_32F, cv::Scalar(std::numeric_limits<float>::infinity()));

    std::vector<cv::Vec3d> q;
    for (const Mesh& mesh : casters) {
        q.resize(mesh.vertices.size());
        for (std::size_t k = 0; k < mesh.vertices.size(); ++k) {
            const cv::Vec3d& p = mesh.vertices[k];
            q[k] = {(u_.dot(p) - origin_.x) / cellMm_, (v_.dot(p) - origin_.y) / cellMm_, w_.dot(p)};
        }
        for (const auto& tri : mesh.triangles) {
            const cv::Vec3d& a = q[static_cast<std::size_t>(tri[0])];
            const cv::Vec3d& b = q[static_cast<std::size_t>(tri[1])];
            const cv::Vec3d& c = q[static_cast<std::size_t>(tri[2])];
            const double area = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
            if (std::abs(area) < 1e-12) continue;  // seen edge-on by the light: it hides nothing
            const int x0 = std::max(0, static_cast<int>(std::ceil(std::min({a[0], b[0], c[0]}))));
            const int x1 = std::min(width - 1, static_cast<int>(std::floor(std::max({a[0], b[0], c[0]}))));
            const int y0 = std::max(0, static_cast<int>(std::ceil(std::min({a[1], b[1], c[1]}))));
            const int y1 = std::min(height - 1, static_cast<int>(std::floor(std::max({a[1], b[1], c[1]}))));
            for (int y = y0; y <= y1; ++y) {
                auto* row = depth_.ptr<float>(y);
                for (int x = x0; x <= x1; ++x) {
                    const double wa = ((b[0] - x) * (c[1] - y) - (c[0] - x) * (b[1] - y)) / area;
                    const double wb = ((c[0] - x) * (a[1] - y) - (a[0] - x) * (c[1] - y)) / area;
                    const double wc = 1.0 - wa - wb;
                    if (wa < 0 || wb < 0 || wc < 0) continue;
                    // Orthographic: depth is linear over the triangle.
                    row[x] = std::min(row[x], static_cast<float>(wa * a[2] + wb * b[2] + wc * c[2]));
                }
            }
        }
    }
}

float ShadowMap::lit(const cv::Vec3d& p) const {
    const double x = (u_.dot(p) - origin_.x) / cellMm_, y = (v_.dot(p) - origin_.y) / cellMm_;
    const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
    if (x0 < 0 || y0 < 0 || x0 + 1 >= depth_.cols || y0 + 1 >= depth_.rows) return 1.0f;
    const float d00 = depth_.at<float>(y0, x0), d01 = depth_.at<float>(y0, x0 + 1);
    const float d10 = depth_.at<float>(y0 + 1, x0), d11 = depth_.at<float>(y0 + 1, x0 + 1);
    double first;
    if (std::isfinite(d00) && std::isfinite(d01) && std::isfinite(d10) && std::isfinite(d11)) {
        // Inside a caster's footprint: bilinear, so that a caster's own surface meets itself.
        const double fx = x - x0, fy = y - y0;
        first = (1 - fy) * ((1 - fx) * d00 + fx * d01) + fy * ((1 - fx) * d10 + fx * d11);
    } else {
        // At the footprint's edge: the nearest cell.
        first = depth_.at<float>(static_cast<int>(std::lround(y)), static_cast<int>(std::lround(x)));
        if (!std::isfinite(first)) return 1.0f;
    }
    return w_.dot(p) > first + kSelfBiasMm ? 0.0f : 1.0f;
}

}  // namespace icewatch::synth
