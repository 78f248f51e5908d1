#pragma once

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/volume/parameters.hpp"

namespace icewatch::volume {

// A frame on the object's mean plane: u, v in the plane, h along the normal towards the camera.
// Ice thickness is the difference of h between the current and the baseline surface.
struct PlaneFrame {
    cv::Vec3d origin;
    cv::Vec3d axisU, axisV, normal;

    cv::Point3d toPlane(const cv::Vec3d& p) const {
        const cv::Vec3d d = p - origin;
        return {d.dot(axisU), d.dot(axisV), d.dot(normal)};
    }
    cv::Vec3d toCamera(double u, double v, double h) const { return origin + u * axisU + v * axisV + h * normal; }

    // Where the ray from `from` along `ray` (camera coordinates) meets the plane; none when it runs
    // parallel to the plane or meets it behind `from` (the plane seen past its horizon).
    std::optional<cv::Vec3d> rayHit(const cv::Vec3d& ray, const cv::Vec3d& from = cv::Vec3d(0, 0, 0)) const {
        const double t = normal.dot(origin - from) / normal.dot(ray);
        if (!(t > 0) || !std::isfinite(t)) return std::nullopt;
        return from + t * ray;
    }
};

// Least-squares plane (PCA) through the points; the normal points towards the camera (origin).
// Throws InvalidInput with fewer than 3 points.
PlaneFrame fitPlane(const std::vector<cv::Vec3d>& points);

// A regular Nu × Nv grid: node (i, j) at (u0 + i·du, v0 + j·dv).
struct GridSpec {
    double u0 = 0, v0 = 0, du = 1, dv = 1;
    int nu = 0, nv = 0;
    double areaPerNodeMm2() const { return du * dv; }
};

// A grid, or why there is none, in words: the scene is not malformed when a region has no grid,
// its outline is, and the chain refuses with the reason.
struct GridOrProblem {
    std::optional<GridSpec> grid;
    std::string problem;
};

// The grid over [uMin, uMax] × [vMin, vMax] with N = ceil(extent / cell) + 1 nodes per axis and
// Δ = extent / (N - 1), as the seed paper defines it; none without a positive, finite extent and
// a positive cell, or with too many nodes.
GridOrProblem gridOver(double uMin, double uMax, double vMin, double vMax, double cellMm);

// The same, throwing InvalidInput with the problem's words.
GridSpec makeGrid(double uMin, double uMax, double vMin, double vMax, double cellMm);

// Linear interpolation of an organised point cloud onto the grid. `planePoints` (CV_64FC3: u, v, h
// per pixel, NaN where there is no point) is triangulated along its pixel lattice (two triangles
// per 2×2 block, one when a corner is missing), which is the Delaunay triangulation of a lattice
// and never bridges a hole; every grid node inside a triangle gets the barycentric blend of its
// corners' h, the mean where noise makes triangles overlap. CV_64F Nv × Nu, NaN = not covered.
//
// Occlusion steps: where a near surface hides part of a far one (the ground just around a block,
// seen from above its top), neighbouring pixels on the two surfaces are far apart in height and
// the triangle between them stands nearly along the line of sight. Interpolating across it would
// build a ramp over ground that is not seen, as if the near surface sloped down to the far one;
// the far surface goes on under the near one instead (the near surface ends in a wall at its own
// edge, the only shape consistent with a surface hidden along the whole band). That edge lies
// anywhere between the near surface's last pixel and the next one, half a pixel beyond the last on
// average. A triangle is a step when one of its edges rises by more than `stepMinMm` and more than
// `stepSlope` times its length in the plane; its nodes within half the lattice's spacing (the
// median distance between neighbouring points of one surface) of its near corner, or of the edge
// between its two near corners, then take the near surface's h, the rest the lowest corner's.
// stepSlope 0: no steps.
// Seen at an angle, the hidden band lies along the line of sight, not along the plane's normal: an
// edge that rises more than `stepMinMm` and runs within atan(1 / stepSlope) of the line from `eye`
// (the camera's centre in the plane frame, when `seenFromEye`) is a step too. Facing the camera,
// the two rules are one.
struct StepOptions {
    double stepSlope = 0;
    double stepMinMm = 0;
    bool seenFromEye = false;
    cv::Vec3d eye = cv::Vec3d(0, 0, 0);
};
cv::Mat interpolateLattice(const cv::Mat& planePoints, const GridSpec& grid, const StepOptions& steps = {});

// Gives every NaN node with `inside` != 0 the value of its nearest non-NaN node. Returns how
// many nodes were filled.
int fillFromNearest(cv::Mat& values, const cv::Mat& inside);

// Box average of the finite values of a CV_64F map over (2r+1)² nodes; NaN where there are none.
cv::Mat finiteBoxMean(const cv::Mat& values, int radius);

// ∫∫ values over the grid, NaN nodes counting as zero. Trapz: trapezoidal rule over u, then v.
// Sum: Σ values·Δu·Δv.
double integrate(const cv::Mat& values, const GridSpec& grid, Integration method);

}  // namespace icewatch::volume
