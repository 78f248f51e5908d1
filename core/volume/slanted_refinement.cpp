#include "core/volume/slanted_refinement.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <Eigen/Dense>
#include <opencv2/imgproc.hpp>

#include "core/common/fixed_bands.hpp"

namespace icewatch::volume {

namespace {

using Vector5 = Eigen::Matrix<double, 5, 1>;
using Matrix5 = Eigen::Matrix<double, 5, 5>;

// The cubic B-spline at fraction t of the way from sample 1 to sample 2 of four coefficients, and
// its derivative. Through prefiltered coefficients (splineCoefficients) it interpolates the
// samples, and its shifts of a texture whose wavelength is a few pixels stay unbiased to a
// thousandth of a pixel, where a linear or a Keys cubic kernel pulls them by a hundredth towards
// the pixels or away from them.
struct Cubic {
    std::array<double, 4> value, slope;
    explicit Cubic(double t) {
        const double s = 1.0 - t, t2 = t * t, t3 = t2 * t;
        value = {s * s * s / 6.0, (3.0 * t3 - 6.0 * t2 + 4.0) / 6.0, (-3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0) / 6.0,
                 t3 / 6.0};
        slope = {-0.5 * s * s, 1.5 * t2 - 2.0 * t, -1.5 * t2 + t + 0.5, 0.5 * t2};
    }
};

// Each row's cubic B-spline coefficients (Unser's recursive prefilter, mirrored at the ends): the
// right eye is only ever interpolated along its rows.
cv::Mat splineCoefficients(const cv::Mat& image) {
    const double z = std::sqrt(3.0) - 2.0;
    cv::Mat coefficients(image.size(), CV_32F);
    const int n = image.cols;
    std::vector<double> c(static_cast<std::size_t>(n));
    for (int y = 0; y < image.rows; ++y) {
        const float* in = image.ptr<float>(y);
        for (int x = 0; x < n; ++x) c[static_cast<std::size_t>(x)] = 6.0 * in[x];
        if (n > 1) {
            // The causal start: the mirrored signal's sum, truncated where z^k is below 1e-9.
            const int horizon = std::min(n, 16);
            double sum = c[0], power = z;
            for (int k = 1; k < horizon; ++k, power *= z) sum += power * c[static_cast<std::size_t>(k)];
            c[0] = sum;
            for (int x = 1; x < n; ++x) c[static_cast<std::size_t>(x)] += z * c[static_cast<std::size_t>(x - 1)];
            c[static_cast<std::size_t>(n - 1)] =
                z / (z * z - 1.0) * (c[static_cast<std::size_t>(n - 1)] + z * c[static_cast<std::size_t>(n - 2)]);
            for (int x = n - 2; x >= 0; --x) {
                c[static_cast<std::size_t>(x)] = z * (c[static_cast<std::size_t>(x + 1)] - c[static_cast<std::size_t>(x)]);
            }
        }
        float* out = coefficients.ptr<float>(y);
        for (int x = 0; x < n; ++x) out[x] = static_cast<float>(c[static_cast<std::size_t>(x)]);
    }
    return coefficients;
}

// Which pixels of a window lie on the centre's surface: each weighted by how far the matcher's
// disparity there is from a plane fitted to the matcher's disparities around the centre (Cauchy
// weights, refitted three times from a plane facing the camera through the centre's value).
// Across a depth step, a block's top against its plate, the other surface's right-eye footprint
// lies elsewhere and would pull the plane towards it, a tenth of a pixel and more within a
// window's radius of the step; the matcher's cross-shaped support keeps to one side of it, and
// here its values tell which side is which. Occluded or unmatched pixels weigh nothing.
// A staircase the matcher's facing windows leave on a slanted surface, steps under a pixel,
// stays within the plane's reach and keeps most of its weight (minSupportShare).
struct WindowSupport {
    std::vector<double> weight;  // (2r+1)^2, row by row
    std::vector<float> window;   // the matcher's disparities under the window (windowSupport's scratch)
    double slopeX = 0, slopeY = 0;
    double total = 0;
};

// Fills `support` (kept by the caller from pixel to pixel: no allocation per pixel).
void windowSupportReference(const cv::Mat& matched, int x, int y, const SlantedRefinement& p, WindowSupport& support) {
    const int r = p.radius;
    const int side = 2 * r + 1;
    support.weight.assign(static_cast<std::size_t>(side * side), 0.0);
    double c = matched.at<float>(y, x), a = 0, b = 0;
    for (int pass = 0; pass <= 3; ++pass) {
        // Weights from the plane of the last pass; the last pass only sets them.
        Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
        Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
        support.total = 0;
        for (int v = -r; v <= r; ++v) {
            const float* m = matched.ptr<float>(y + v);
            for (int u = -r; u <= r; ++u) {
                double& w = support.weight[static_cast<std::size_t>((v + r) * side + u + r)];
                const float d = m[x + u];
                if (!(d >= 0)) {
                    w = 0;
                    continue;
                }
                const double off = (d - (c + a * u + b * v)) / p.supportPx;
                w = 1.0 / (1.0 + off * off);
                support.total += w;
                const Eigen::Vector3d j(1.0, u, v);
                normal += w * j * j.transpose();
                rhs += w * d * j;
            }
        }
        if (pass == 3) break;
        const Eigen::Vector3d plane = normal.ldlt().solve(rhs);
        if (!plane.allFinite()) break;
        c = plane[0];
        a = plane[1];
        b = plane[2];
    }
    support.slopeX = a;
    support.slopeY = b;
}

// What a window's fit returns when hopeless() stopped it (any negative value: the matcher's stands).
constexpr double kGaveUp = -2.0;

// Whether a window, at this step of its fit, has gone where it will not come back from: past its
// first giveUpAfterSteps steps, the disparity's standard error (from the residual and the normal
// matrix) is over giveUpFactor times the largest a result may have. A blank window (sky, white
// ice) otherwise runs all its steps, or converges on a gain no light gives, and is refused then.
bool hopeless(const Eigen::LDLT<Matrix5>& solver, double squares, double total, int step, const SlantedRefinement& p) {
    if (step < p.giveUpAfterSteps) return false;
    if (!(total > 5.0)) return true;
    const Vector5 first = solver.solve(Vector5::Unit(0));
    const double variance = first[0] * squares / (total - 5.0);
    const double limit = p.giveUpFactor * p.maxSigmaPx;
    return variance > limit * limit;
}

// windowSupportReference with its sums written out (the normal matrix is symmetric: six sums and
// three for the right-hand side) and the window's disparities read once for its four passes.
void windowSupport(const cv::Mat& matched, int x, int y, const SlantedRefinement& p, WindowSupport& support) {
    const int r = p.radius;
    const int side = 2 * r + 1;
    const auto n = static_cast<std::size_t>(side * side);
    support.weight.assign(n, 0.0);
    support.window.resize(n);
    for (int v = -r; v <= r; ++v) {
        const float* m = matched.ptr<float>(y + v) + x;
        float* to = support.window.data() + (v + r) * side + r;
        for (int u = -r; u <= r; ++u) to[u] = m[u];
    }
    double c = matched.at<float>(y, x), a = 0, b = 0;
    for (int pass = 0; pass <= 3; ++pass) {
        double s1 = 0, su = 0, sv = 0, suu = 0, suv = 0, svv = 0, sd = 0, sdu = 0, sdv = 0;
        for (int v = -r; v <= r; ++v) {
            const float* window = support.window.data() + (v + r) * side + r;
            double* weights = support.weight.data() + (v + r) * side + r;
            const double rowPlane = c + b * v;
            double r1 = 0, ru = 0, ruu = 0, rd = 0, rdu = 0;
            for (int u = -r; u <= r; ++u) {
                const float d = window[u];
                if (!(d >= 0)) continue;  // the weight stays 0
                const double off = (d - (rowPlane + a * u)) / p.supportPx;
                const double w = 1.0 / (1.0 + off * off);
                weights[u] = w;
                r1 += w;
                ru += w * u;
                ruu += w * u * u;
                rd += w * d;
                rdu += w * d * u;
            }
            s1 += r1;
            su += ru;
            sv += r1 * v;
            suu += ruu;
            suv += ru * v;
            svv += r1 * v * v;
            sd += rd;
            sdu += rdu;
            sdv += rd * v;
        }
        support.total = s1;
        if (pass == 3) break;
        Eigen::Matrix3d normal;
        normal << s1, su, sv, su, suu, suv, sv, suv, svv;
        const Eigen::Vector3d plane = normal.ldlt().solve(Eigen::Vector3d(sd, sdu, sdv));
        if (!plane.allFinite()) break;
        c = plane[0];
        a = plane[1];
        b = plane[2];
    }
    support.slopeX = a;
    support.slopeY = b;
}

// The normal equations of one window's fit at the parameters q: the 5x5 matrix JᵀWJ, the
// right-hand side JᵀWe and the weighted squared residual, J = (dx, dx·u, dx·v, value, 1), dx the
// model's derivative along the disparity, the model m = gain · R(xr) + offset (xr falls as the
// disparity rises). False when the footprint left the image.
struct NormalEquations {
    Matrix5 h;
    Vector5 g;
    double squares = 0;
};

// The sums the normal equations are made of (the first character or two say which Jacobian
// columns: x the disparity's, r the value's; u and v their moments; e the residual).
struct Sums {
    double xx = 0, xxu = 0, xxv = 0, xxuu = 0, xxuv = 0, xxvv = 0;
    double xr1 = 0, xru = 0, xrv = 0, x1 = 0, xu = 0, xv = 0, rr = 0, r1 = 0;
    double xe = 0, xue = 0, xve = 0, re = 0, e1 = 0, w1 = 0;
    double squares = 0;

    void assemble(NormalEquations& out) const {
        out.h << xx, xxu, xxv, xr1, x1,
                 xxu, xxuu, xxuv, xru, xu,
                 xxv, xxuv, xxvv, xrv, xv,
                 xr1, xru, xrv, rr, r1,
                 x1, xu, xv, r1, w1;
        out.g << xe, xue, xve, re, e1;
        out.squares = squares;
    }
};

// The sums as the equations read, pixel by pixel: the reference the fast form is held to.
bool normalEquationsReference(const cv::Mat& left, const cv::Mat& right, int x, int y, const Vector5& q,
                              const WindowSupport& support, int r, NormalEquations& out) {
    const int side = 2 * r + 1;
    Sums m;
    for (int v = -r; v <= r; ++v) {
        const float* l = left.ptr<float>(y + v);
        const float* row = right.ptr<float>(y + v);
        const double* weights = support.weight.data() + (v + r) * side + r;
        const double rowStart = x - q[0] - q[2] * v;
        for (int u = -r; u <= r; ++u) {
            const double w = weights[u];
            if (w == 0.0) continue;
            const double xr = rowStart + u * (1.0 - q[1]);
            const double base = std::floor(xr);
            const int i = static_cast<int>(base);
            if (i < 1 || i + 2 >= right.cols) return false;
            const Cubic c(xr - base);
            const float* s = row + i - 1;
            const double value = c.value[0] * s[0] + c.value[1] * s[1] + c.value[2] * s[2] + c.value[3] * s[3];
            const double slope = c.slope[0] * s[0] + c.slope[1] * s[1] + c.slope[2] * s[2] + c.slope[3] * s[3];
            const double e = w * (l[x + u] - (q[3] * value + q[4]));
            const double dx = -q[3] * slope;
            const double wdx = w * dx;
            const double dxdx = wdx * dx;
            m.xx += dxdx;
            m.xxu += dxdx * u;
            m.xxv += dxdx * v;
            m.xxuu += dxdx * u * u;
            m.xxuv += dxdx * u * v;
            m.xxvv += dxdx * v * v;
            m.xr1 += wdx * value;
            m.xru += wdx * value * u;
            m.xrv += wdx * value * v;
            m.x1 += wdx;
            m.xu += wdx * u;
            m.xv += wdx * v;
            m.rr += w * value * value;
            m.r1 += w * value;
            m.w1 += w;
            // e carries the weight once: J'We and e'e/w summed below.
            m.xe += dx * e;
            m.xue += dx * u * e;
            m.xve += dx * v * e;
            m.re += value * e;
            m.e1 += e;
            m.squares += e * e / w;
        }
    }
    m.assemble(out);
    return true;
}

// normalEquationsReference with the sums taken row by row: the moments in v come from each
// row's sums once per row instead of once per pixel, and the cubic's weights are written out
// where they are used. The same equations; the sums' order differs.
bool normalEquations(const cv::Mat& left, const cv::Mat& right, int x, int y, const Vector5& q,
                     const WindowSupport& support, int r, NormalEquations& out) {
    const int side = 2 * r + 1;
    const int lastColumn = right.cols - 3;
    const double gain = q[3], offset = q[4], stepU = 1.0 - q[1];
    Sums m;
    for (int v = -r; v <= r; ++v) {
        const float* l = left.ptr<float>(y + v) + x;
        const float* row = right.ptr<float>(y + v);
        const double* weights = support.weight.data() + (v + r) * side + r;
        const double rowStart = x - q[0] - q[2] * v;
        // This row's sums of dx², dx·value, dx and dx·e, each alone and times u, and of dx²·u².
        double a1 = 0, au = 0, auu = 0, b1 = 0, bu = 0, c1 = 0, cu = 0, d1 = 0, du = 0;
        for (int u = -r; u <= r; ++u) {
            const double w = weights[u];
            if (w == 0.0) continue;
            const double xr = rowStart + u * stepU;
            const double base = std::floor(xr);
            const int i = static_cast<int>(base);
            if (i < 1 || i > lastColumn) return false;
            const double t = xr - base, o = 1.0 - t, t2 = t * t, t3 = t2 * t;
            const float* s = row + i - 1;
            const double value =
                (o * o * o * s[0] + (3.0 * t3 - 6.0 * t2 + 4.0) * s[1] + (-3.0 * t3 + 3.0 * t2 + 3.0 * t + 1.0) * s[2] +
                 t3 * s[3]) /
                6.0;
            const double slope =
                -0.5 * o * o * s[0] + (1.5 * t2 - 2.0 * t) * s[1] + (-1.5 * t2 + t + 0.5) * s[2] + 0.5 * t2 * s[3];
            const double e = w * (l[u] - (gain * value + offset));
            const double dx = -gain * slope;
            const double wdx = w * dx;
            const double dxdx = wdx * dx;
            a1 += dxdx;
            au += dxdx * u;
            auu += dxdx * u * u;
            b1 += wdx * value;
            bu += wdx * value * u;
            c1 += wdx;
            cu += wdx * u;
            d1 += dx * e;
            du += dx * u * e;
            m.rr += w * value * value;
            m.r1 += w * value;
            m.w1 += w;
            m.re += value * e;
            m.e1 += e;
            m.squares += e * e / w;
        }
        m.xx += a1;
        m.xxu += au;
        m.xxv += a1 * v;
        m.xxuu += auu;
        m.xxuv += au * v;
        m.xxvv += a1 * v * v;
        m.xr1 += b1;
        m.xru += bu;
        m.xrv += b1 * v;
        m.x1 += c1;
        m.xu += cu;
        m.xv += c1 * v;
        m.xe += d1;
        m.xue += du;
        m.xve += d1 * v;
    }
    m.assemble(out);
    return true;
}

// One pixel's window, from the matcher's value `start`, weighted and started on the slopes of
// `support`, its normal equations from `equationsAt(q, out)`. Returns the refined disparity, or
// a negative value where the matcher's stands (kGaveUp when hopeless() stopped it).
template <class Equations>
double fitWindow(double start, const WindowSupport& support, const SlantedRefinement& p, const Equations& equationsAt) {
    const int side = 2 * p.radius + 1;
    // A window much of which lies off the centre's surface, beside a depth step or astride a
    // hole, is where the matcher's cross-shaped support does better: its value stands.
    if (support.total < p.minSupportShare * side * side) return -1.0;
    // Parameters: disparity, its slopes along x and y, the right eye's gain and offset.
    Vector5 q;
    q << start, support.slopeX, support.slopeY, 1.0, 0.0;
    bool converged = false;
    NormalEquations at;
    for (int iteration = 0; iteration < p.iterations; ++iteration) {
        if (!equationsAt(q, at)) return -1.0;  // the footprint left the image
        const Eigen::LDLT<Matrix5> solver(at.h);
        if (solver.info() != Eigen::Success) return -1.0;
        if (hopeless(solver, at.squares, support.total, iteration, p)) return kGaveUp;
        const Vector5 step = solver.solve(at.g);
        if (!step.allFinite()) return -1.0;
        q += step;
        if (std::abs(q[0] - start) > p.maxChangePx) return -1.0;
        if (std::abs(step[0]) < 1e-3) {
            converged = true;
            break;
        }
    }
    if (!converged || q[3] < 0.5 || q[3] > 2.0) return -1.0;
    // The disparity's variance: the residual's, through the inverse of the normal matrix.
    const Matrix5 covariance = at.h.inverse() * (at.squares / (support.total - 5));
    if (!(covariance(0, 0) >= 0) || std::sqrt(covariance(0, 0)) > p.maxSigmaPx) return -1.0;
    return q[0];
}

// The window at (x, y); `right` holds the right eye's spline coefficients.
double refinePixelReference(const cv::Mat& left, const cv::Mat& right, int x, int y, double start,
                            const WindowSupport& support, const SlantedRefinement& p) {
    return fitWindow(start, support, p, [&](const Vector5& q, NormalEquations& out) {
        return normalEquationsReference(left, right, x, y, q, support, p.radius, out);
    });
}

double refinePixel(const cv::Mat& left, const cv::Mat& right, int x, int y, double start, const WindowSupport& support,
                   const SlantedRefinement& p) {
    return fitWindow(start, support, p, [&](const Vector5& q, NormalEquations& out) {
        return normalEquations(left, right, x, y, q, support, p.radius, out);
    });
}

// Every pixel of `area` (and `where`) that has a matcher's disparity, through the window's
// support and fit given: the reference pair or the fast one.
template <class Support, class Refine>
SlantedRefinementCount refineEach(const cv::Mat& left, const cv::Mat& right, const cv::Rect& area,
                                  const SlantedRefinement& parameters, cv::Mat& disparity, const cv::Mat& where,
                                  const Support& windowSupportOf, const Refine& refineAt) {
    CV_Assert(left.type() == CV_32FC1 && right.type() == CV_32FC1 && disparity.type() == CV_32FC1);
    CV_Assert(left.size() == right.size() && left.size() == disparity.size() && parameters.radius >= 1);
    CV_Assert(where.empty() || (where.type() == CV_8UC1 && where.size() == disparity.size()));
    const int r = parameters.radius;
    const cv::Rect inside = area & cv::Rect(r, r, left.cols - 2 * r, left.rows - 2 * r);
    if (inside.empty()) return {};
    const cv::Mat matched = disparity.clone();
    const cv::Mat rightSpline = splineCoefficients(right);
    std::array<int, kFixedBands> refined{}, kept{}, gaveUp{};
    forEachFixedBand(static_cast<std::size_t>(inside.height), [&](int band, std::size_t begin, std::size_t end) {
        WindowSupport support;
        for (auto row = begin; row < end; ++row) {
            const int y = inside.y + static_cast<int>(row);
            const float* m = matched.ptr<float>(y);
            const std::uint8_t* wanted = where.empty() ? nullptr : where.ptr<std::uint8_t>(y);
            float* out = disparity.ptr<float>(y);
            for (int x = inside.x; x < inside.x + inside.width; ++x) {
                if (m[x] < 0 || (wanted && !wanted[x])) continue;
                windowSupportOf(matched, x, y, parameters, support);
                const double d = refineAt(left, rightSpline, x, y, m[x], support, parameters);
                if (d >= 0) {
                    out[x] = static_cast<float>(d);
                    ++refined[static_cast<std::size_t>(band)];
                } else {
                    ++kept[static_cast<std::size_t>(band)];
                    if (d == kGaveUp) ++gaveUp[static_cast<std::size_t>(band)];
                }
            }
        }
    });
    SlantedRefinementCount count;
    for (int b = 0; b < kFixedBands; ++b) {
        count.refined += refined[static_cast<std::size_t>(b)];
        count.kept += kept[static_cast<std::size_t>(b)];
        count.gaveUp += gaveUp[static_cast<std::size_t>(b)];
    }
    return count;
}

}  // namespace

SlantedRefinementCount refineSlanted(const cv::Mat& left, const cv::Mat& right, const cv::Rect& area,
                                     const SlantedRefinement& parameters, cv::Mat& disparity, const cv::Mat& where) {
    return refineEach(left, right, area, parameters, disparity, where, windowSupport, refinePixel);
}

SlantedRefinementCount refineSlantedReference(const cv::Mat& left, const cv::Mat& right, const cv::Rect& area,
                                              const SlantedRefinement& parameters, cv::Mat& disparity,
                                              const cv::Mat& where) {
    return refineEach(left, right, area, parameters, disparity, where, windowSupportReference, refinePixelReference);
}

}  // namespace icewatch::volume
