// From scattered points to a volume: the object's plane frame, the regular grid, linear
// interpolation of the points onto it and the two integration rules of the seed paper.
#include "core/volume/height_grid.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "core/common/error.hpp"
#include "core/volume/robust_statistics.hpp"

namespace icewatch::volume {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
}

PlaneFrame fitPlane(const std::vector<cv::Vec3d>& points) {
    if (points.size() < 3) {
        throw InvalidInput("plane fit needs at least 3 points");
    }
    cv::Vec3d mean(0, 0, 0);
    for (const auto& p : points) mean += p;
    mean /= static_cast<double>(points.size());
    cv::Matx33d scatter = cv::Matx33d::zeros();
    for (const auto& p : points) {
        const cv::Vec3d d = p - mean;
        scatter += d * d.t();
    }
    cv::Mat eigenvalues, eigenvectors;
    cv::eigen(cv::Mat(scatter), eigenvalues, eigenvectors);  // descending eigenvalues
    PlaneFrame frame;
    frame.origin = mean;
    frame.axisU = cv::Vec3d(eigenvectors.row(0));
    frame.normal = cv::Vec3d(eigenvectors.row(2));
    if (frame.normal.dot(mean) > 0) {
        frame.normal = -frame.normal;  // towards the camera
    }
    // Keep u roughly along the image's x for readable maps, and the frame right-handed.
    if (frame.axisU[0] < 0) frame.axisU = -frame.axisU;
    frame.axisV = frame.normal.cross(frame.axisU);
    return frame;
}

GridOrProblem gridOver(double uMin, double uMax, double vMin, double vMax, double cellMm) {
    if (!(uMax > uMin) || !(vMax > vMin) || !(cellMm > 0)) {
        return {std::nullopt, "grid: the region must have a positive extent and the cell a positive size"};
    }
    // Counted in floating point first: an extent of kilometres (or an infinite one) would overflow
    // the cast to int before any bound on the count could see it.
    const double nu = std::ceil((uMax - uMin) / cellMm) + 1;
    const double nv = std::ceil((vMax - vMin) / cellMm) + 1;
    if (!std::isfinite(nu * nv) || nu * nv > 5e7) {
        std::ostringstream what;
        what << std::fixed << std::setprecision(0) << "grid: " << nu << " x " << nv << " nodes is too many; use a larger cell";
        return {std::nullopt, what.str()};
    }
    GridSpec grid;
    grid.nu = static_cast<int>(nu);
    grid.nv = static_cast<int>(nv);
    grid.u0 = uMin;
    grid.v0 = vMin;
    grid.du = (uMax - uMin) / (grid.nu - 1);
    grid.dv = (vMax - vMin) / (grid.nv - 1);
    return {grid, {}};
}

GridSpec makeGrid(double uMin, double uMax, double vMin, double vMax, double cellMm) {
    GridOrProblem made = gridOver(uMin, uMax, vMin, vMax, cellMm);
    if (!made.grid) throw InvalidInput(made.problem);
    return *made.grid;
}

namespace {

// The median distance on the plane between a point and its right-hand neighbour on the lattice,
// where both lie on one surface (their heights within `stepMm`); 0 without such pairs.
double latticeSpacing(const cv::Mat& planePoints, double stepMm) {
    std::vector<double> distances;
    for (int y = 0; y < planePoints.rows; ++y) {
        const auto* row = planePoints.ptr<cv::Vec3d>(y);
        for (int x = 0; x + 1 < planePoints.cols; ++x) {
            const cv::Vec3d &p = row[x], &q = row[x + 1];
            if (std::isnan(p[2]) || std::isnan(q[2]) || std::abs(p[2] - q[2]) > stepMm) continue;
            distances.push_back(std::hypot(q[0] - p[0], q[1] - p[1]));
        }
    }
    if (distances.empty()) return 0.0;
    return median(std::move(distances));
}

}  // namespace

cv::Mat interpolateLattice(const cv::Mat& planePoints, const GridSpec& grid, const StepOptions& steps) {
    CV_Assert(planePoints.type() == CV_64FC3);
    // Noise moves points sideways as well as in depth, so neighbouring triangles can overlap a
    // little: a node covered twice gets the mean (taking the front one would bias upwards).
    cv::Mat sum(grid.nv, grid.nu, CV_64F, cv::Scalar(0.0)), count(grid.nv, grid.nu, CV_32S, cv::Scalar(0));
    auto valid = [](const cv::Vec3d& p) { return !std::isnan(p[2]); };
    // cos(atan(1 / stepSlope)): an edge within that angle of the line of sight.
    const double alongSight = steps.stepSlope > 0 ? steps.stepSlope / std::hypot(1.0, steps.stepSlope) : 1.0;
    // Half the lattice's spacing on the plane: how far, on average, a near surface goes on beyond
    // its last pixel before its wall (its edge lies anywhere between that pixel and the next).
    const double halfSpacing = steps.stepSlope > 0 ? 0.5 * latticeSpacing(planePoints, steps.stepMinMm) : 0.0;
    auto rasterTriangle = [&](const cv::Vec3d& a, const cv::Vec3d& b, const cv::Vec3d& c) {
        // In grid index space.
        const double ax = (a[0] - grid.u0) / grid.du, ay = (a[1] - grid.v0) / grid.dv;
        const double bx = (b[0] - grid.u0) / grid.du, by = (b[1] - grid.v0) / grid.dv;
        const double cx = (c[0] - grid.u0) / grid.du, cy = (c[1] - grid.v0) / grid.dv;
        const double area = (bx - ax) * (cy - ay) - (cx - ax) * (by - ay);
        if (std::abs(area) < 1e-12) return;
        const int x0 = std::max(0, static_cast<int>(std::ceil(std::min({ax, bx, cx}))));
        const int x1 = std::min(grid.nu - 1, static_cast<int>(std::floor(std::max({ax, bx, cx}))));
        const int y0 = std::max(0, static_cast<int>(std::ceil(std::min({ay, by, cy}))));
        const int y1 = std::min(grid.nv - 1, static_cast<int>(std::floor(std::max({ay, by, cy}))));
        const double invArea = 1.0 / area;
        // An occlusion step: the far (lowest) surface continues under the near one.
        auto rises = [&steps, alongSight](const cv::Vec3d& p, const cv::Vec3d& q) {
            const double dh = std::abs(p[2] - q[2]);
            if (dh <= steps.stepMinMm) return false;
            if (dh > steps.stepSlope * std::hypot(p[0] - q[0], p[1] - q[1])) return true;
            if (!steps.seenFromEye) return false;
            const cv::Vec3d edge = q - p, sight = 0.5 * (p + q) - steps.eye;
            return std::abs(edge.dot(sight)) > alongSight * cv::norm(edge) * cv::norm(sight);
        };
        const bool step = steps.stepSlope > 0 && (rises(a, b) || rises(b, c) || rises(a, c));
        const double lowest = std::min({a[2], b[2], c[2]});
        // The corners on the near surface, within a step of the highest: one or two, since a step
        // rises by more than that (only a step's nodes ask).
        const cv::Vec3d* near[2] = {nullptr, nullptr};
        int nearCount = 0;
        if (step) {
            const double highest = std::max({a[2], b[2], c[2]});
            for (const cv::Vec3d* corner : {&a, &b, &c})
                if (highest - (*corner)[2] <= steps.stepMinMm && nearCount < 2) near[nearCount++] = corner;
        }
        // A step's node on the near surface when it lies within half the spacing of the near
        // corner (or of the edge between the two near corners), the far surface's beyond: the
        // near surface ends in a wall at its own edge, which lies half a pixel beyond its last
        // pixel on average. The lowest corner for every node left a ring of half a pixel of every
        // block's top out (its height times half a pixel along its perimeter, 2 % of a block).
        auto stepHeight = [&](double px, double py) {
            const cv::Vec3d& p0 = *near[0];
            const cv::Vec3d& p1 = nearCount == 2 ? *near[1] : p0;
            const double ex = p1[0] - p0[0], ey = p1[1] - p0[1], length2 = ex * ex + ey * ey;
            const double t = length2 > 0 ? std::clamp(((px - p0[0]) * ex + (py - p0[1]) * ey) / length2, 0.0, 1.0) : 0.0;
            const double dx = px - (p0[0] + t * ex), dy = py - (p0[1] + t * ey);
            return dx * dx + dy * dy < halfSpacing * halfSpacing ? p0[2] + t * (p1[2] - p0[2]) : lowest;
        };
        constexpr double kEdge = -1e-9;  // nodes exactly on a shared edge belong to both
        for (int y = y0; y <= y1; ++y) {
            auto* sumRow = sum.ptr<double>(y);
            auto* countRow = count.ptr<int>(y);
            for (int x = x0; x <= x1; ++x) {
                const double wa = ((bx - x) * (cy - y) - (cx - x) * (by - y)) * invArea;
                const double wb = ((cx - x) * (ay - y) - (ax - x) * (cy - y)) * invArea;
                const double wc = 1.0 - wa - wb;
                if (wa < kEdge || wb < kEdge || wc < kEdge) continue;
                const double h = step ? stepHeight(grid.u0 + x * grid.du, grid.v0 + y * grid.dv)
                                      : wa * a[2] + wb * b[2] + wc * c[2];
                sumRow[x] += h;
                ++countRow[x];
            }
        }
    };
    for (int y = 0; y + 1 < planePoints.rows; ++y) {
        const auto* top = planePoints.ptr<cv::Vec3d>(y);
        const auto* bottom = planePoints.ptr<cv::Vec3d>(y + 1);
        for (int x = 0; x + 1 < planePoints.cols; ++x) {
            const cv::Vec3d &a = top[x], &b = top[x + 1], &c = bottom[x], &d = bottom[x + 1];
            const bool va = valid(a), vb = valid(b), vc = valid(c), vd = valid(d);
            const int corners = va + vb + vc + vd;
            if (corners == 4) {
                rasterTriangle(a, b, d);
                rasterTriangle(a, d, c);
            } else if (corners == 3) {
                if (!va) rasterTriangle(b, d, c);
                if (!vb) rasterTriangle(a, d, c);
                if (!vc) rasterTriangle(a, b, d);
                if (!vd) rasterTriangle(a, b, c);
            }
        }
    }
    cv::Mat values(grid.nv, grid.nu, CV_64F, cv::Scalar(kNaN));
    for (int y = 0; y < grid.nv; ++y)
        for (int x = 0; x < grid.nu; ++x) {
            const int n = count.at<int>(y, x);
            if (n > 0) values.at<double>(y, x) = sum.at<double>(y, x) / n;
        }
    return values;
}

int fillFromNearest(cv::Mat& values, const cv::Mat& inside) {
    CV_Assert(values.type() == CV_64F && inside.type() == CV_8U && inside.size() == values.size());
    cv::Mat sources(values.size(), CV_8U);
    int missing = 0, present = 0;
    for (int y = 0; y < values.rows; ++y) {
        const auto* v = values.ptr<double>(y);
        const auto* in = inside.ptr<std::uint8_t>(y);
        auto* s = sources.ptr<std::uint8_t>(y);
        for (int x = 0; x < values.cols; ++x) {
            const bool have = !std::isnan(v[x]);
            s[x] = have ? 0 : 255;  // distanceTransform measures to the zero pixels
            present += have;
            missing += (!have && in[x]);
        }
    }
    if (missing == 0 || present == 0) {
        return 0;
    }
    cv::Mat distance, labels;
    cv::distanceTransform(sources, distance, labels, cv::DIST_L2, cv::DIST_MASK_5, cv::DIST_LABEL_PIXEL);
    std::vector<double> valueOfLabel(static_cast<std::size_t>(present) + 2, kNaN);
    for (int y = 0; y < values.rows; ++y) {
        const auto* v = values.ptr<double>(y);
        const auto* l = labels.ptr<int>(y);
        for (int x = 0; x < values.cols; ++x) {
            if (!std::isnan(v[x])) {
                const auto label = static_cast<std::size_t>(l[x]);
                if (label >= valueOfLabel.size()) valueOfLabel.resize(label + 1, kNaN);
                valueOfLabel[label] = v[x];
            }
        }
    }
    int filled = 0;
    for (int y = 0; y < values.rows; ++y) {
        auto* v = values.ptr<double>(y);
        const auto* in = inside.ptr<std::uint8_t>(y);
        const auto* l = labels.ptr<int>(y);
        for (int x = 0; x < values.cols; ++x) {
            if (in[x] && std::isnan(v[x])) {
                const auto label = static_cast<std::size_t>(l[x]);
                if (label < valueOfLabel.size() && !std::isnan(valueOfLabel[label])) {
                    v[x] = valueOfLabel[label];
                    ++filled;
                }
            }
        }
    }
    return filled;
}

double integrate(const cv::Mat& values, const GridSpec& grid, Integration method) {
    CV_Assert(values.type() == CV_64F && values.rows == grid.nv && values.cols == grid.nu);
    auto at = [&](int y, int x) {
        const double v = values.at<double>(y, x);
        return std::isnan(v) ? 0.0 : v;
    };
    if (method == Integration::Sum) {
        double sum = 0;
        for (int y = 0; y < grid.nv; ++y)
            for (int x = 0; x < grid.nu; ++x) sum += at(y, x);
        return sum * grid.du * grid.dv;
    }
    std::vector<double> rowIntegral(static_cast<std::size_t>(grid.nv), 0.0);
    for (int y = 0; y < grid.nv; ++y) {
        double s = 0;
        for (int x = 0; x + 1 < grid.nu; ++x) s += 0.5 * (at(y, x) + at(y, x + 1)) * grid.du;
        rowIntegral[static_cast<std::size_t>(y)] = s;
    }
    double volume = 0;
    for (std::size_t y = 0; y + 1 < rowIntegral.size(); ++y) {
        volume += 0.5 * (rowIntegral[y] + rowIntegral[y + 1]) * grid.dv;
    }
    return volume;
}

cv::Mat finiteBoxMean(const cv::Mat& values, int radius) {
    CV_Assert(values.type() == CV_64FC1);
    cv::Mat finite = values.clone(), weight(values.size(), CV_64F);
    for (int y = 0; y < values.rows; ++y)
        for (int x = 0; x < values.cols; ++x) {
            const bool ok = !std::isnan(values.at<double>(y, x));
            weight.at<double>(y, x) = ok ? 1.0 : 0.0;
            if (!ok) finite.at<double>(y, x) = 0.0;
        }
    const cv::Size window(2 * radius + 1, 2 * radius + 1);
    cv::boxFilter(finite, finite, CV_64F, window, {-1, -1}, false);
    cv::boxFilter(weight, weight, CV_64F, window, {-1, -1}, false);
    cv::Mat mean(values.size(), CV_64F);
    for (int y = 0; y < values.rows; ++y)
        for (int x = 0; x < values.cols; ++x) {
            const double w = weight.at<double>(y, x);
            mean.at<double>(y, x) = w > 0 ? finite.at<double>(y, x) / w : std::numeric_limits<double>::quiet_NaN();
        }
    return mean;
}

}  // namespace icewatch::volume
