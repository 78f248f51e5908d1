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
#include "core/common/simd.hpp"

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
// The fast kernels work on a window's rows as vectors (cv::v_float32: 8 lanes with AVX2, 4 with
// SSE or NEON), each row padded to a whole number of vectors with pixels that weigh nothing, and
// sum in single precision within the window: a window's sums run over 169 pixels of grey levels
// under 256, well inside a float's precision (the reference sums in double; a test holds the two
// within the fit's stopping step, 1e-3 px, and within 1e-4 px on all but a per mille of windows).
struct LaneRows {
    int side = 0, stride = 0;  // pixels in a window's row, and floats a padded row holds
    std::vector<float> u;      // each padded column's u (-r … ), the padding past r included
    explicit LaneRows(int radius) : side(2 * radius + 1) {
        constexpr int kLanes = cv::v_float32::nlanes;
        stride = (side + kLanes - 1) / kLanes * kLanes;
        u.resize(static_cast<std::size_t>(stride));
        for (int k = 0; k < stride; ++k) u[static_cast<std::size_t>(k)] = static_cast<float>(k - radius);
    }
};

struct WindowSupport {
    std::vector<double> weight;  // (2r+1)^2, row by row (the reference)
    LaneRows rows{0};            // the fast kernels' layout of a window
    std::vector<float> laneWeight;  // the weights in that layout (windowSupport)
    std::vector<float> window;   // the matcher's disparities under the window (windowSupport's scratch)
    std::vector<float> leftWindow;  // the left eye under it (copyLeftWindow)
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
// inverse00: the disparity's entry of the normal matrix's inverse.
bool hopeless(double inverse00, double squares, double total, int step, const SlantedRefinement& p) {
    if (step < p.giveUpAfterSteps) return false;
    if (!(total > 5.0)) return true;
    const double variance = inverse00 * squares / (total - 5.0);
    const double limit = p.giveUpFactor * p.maxSigmaPx;
    return variance > limit * limit;
}

// windowSupportReference on vectors: the window's disparities read once for its four passes (the
// padding as holes), the weights written into support.laneWeight for the fit. The normal matrix is
// symmetric: six sums, and three for the right-hand side, their moments in v taken per row.
void windowSupport(const cv::Mat& matched, int x, int y, const SlantedRefinement& p, WindowSupport& support) {
    constexpr int kLanes = cv::v_float32::nlanes;
    const int r = p.radius;
    if (support.rows.side != 2 * r + 1) support.rows = LaneRows(r);
    const LaneRows& rows = support.rows;
    const int stride = rows.stride;
    support.window.assign(static_cast<std::size_t>(rows.side * stride), -1.0f);
    support.laneWeight.assign(support.window.size(), 0.0f);
    for (int v = -r; v <= r; ++v) {
        const float* m = matched.ptr<float>(y + v) + x - r;
        std::copy(m, m + rows.side, support.window.data() + (v + r) * stride);
    }
    const cv::v_float32 zero = cv::vx_setzero_f32(), one = cv::vx_setall_f32(1.0f);
    const cv::v_float32 inverseReach = cv::vx_setall_f32(static_cast<float>(1.0 / p.supportPx));
    double c = matched.at<float>(y, x), a = 0, b = 0;
    for (int pass = 0; pass <= 3; ++pass) {
        cv::v_float32 s1 = zero, su = zero, sv = zero, suu = zero, suv = zero, svv = zero, sd = zero, sdu = zero,
                      sdv = zero;
        const cv::v_float32 slopeU = cv::vx_setall_f32(static_cast<float>(a));
        for (int v = -r; v <= r; ++v) {
            const float* window = support.window.data() + (v + r) * stride;
            float* weights = support.laneWeight.data() + (v + r) * stride;
            const cv::v_float32 rowPlane = cv::vx_setall_f32(static_cast<float>(c + b * v));
            cv::v_float32 r1 = zero, ru = zero, ruu = zero, rd = zero, rdu = zero;
            for (int k = 0; k < stride; k += kLanes) {
                const cv::v_float32 d = cv::vx_load(window + k), u = cv::vx_load(rows.u.data() + k);
                const cv::v_float32 off = (d - cv::v_fma(slopeU, u, rowPlane)) * inverseReach;
                // A hole (negative or NaN) weighs nothing.
                const cv::v_float32 w = cv::v_select(d >= zero, one / cv::v_fma(off, off, one), zero);
                cv::v_store(weights + k, w);
                const cv::v_float32 wu = w * u, wd = w * d;
                r1 += w;
                ru += wu;
                ruu = cv::v_fma(wu, u, ruu);
                rd += wd;
                rdu = cv::v_fma(wd, u, rdu);
            }
            const cv::v_float32 fv = cv::vx_setall_f32(static_cast<float>(v));
            s1 += r1;
            su += ru;
            sv = cv::v_fma(r1, fv, sv);
            suu += ruu;
            suv = cv::v_fma(ru, fv, suv);
            svv = cv::v_fma(r1 * fv, fv, svv);
            sd += rd;
            sdu += rdu;
            sdv = cv::v_fma(rd, fv, sdv);
        }
        support.total = cv::v_reduce_sum(s1);
        if (pass == 3) break;
        const double n1 = support.total, nu = cv::v_reduce_sum(su), nv = cv::v_reduce_sum(sv),
                     nuv = cv::v_reduce_sum(suv);
        Eigen::Matrix3d normal;
        normal << n1, nu, nv, nu, cv::v_reduce_sum(suu), nuv, nv, nuv, cv::v_reduce_sum(svv);
        const Eigen::Vector3d plane =
            normal.ldlt().solve(Eigen::Vector3d(cv::v_reduce_sum(sd), cv::v_reduce_sum(sdu), cv::v_reduce_sum(sdv)));
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

// normalEquationsReference on vectors along each row of the window (LaneRows; the left eye's
// window copied into that layout by copyLeftWindow): the moments in v come from each row's sums
// once per row instead of once per pixel, the right eye's four spline coefficients under each
// lane are gathered, and e·e/w is summed as w·(residual)², which is the same where w > 0 and
// needs no division where the padding weighs nothing.
bool normalEquations(const cv::Mat& right, int x, int y, const Vector5& q, const WindowSupport& support, int r,
                     NormalEquations& out) {
    constexpr int kLanes = cv::v_float32::nlanes;
    const LaneRows& rows = support.rows;
    const int stride = rows.stride;
    const cv::v_float32 zero = cv::vx_setzero_f32(), one = cv::vx_setall_f32(1.0f);
    const cv::v_float32 gain = cv::vx_setall_f32(static_cast<float>(q[3])),
                        offset = cv::vx_setall_f32(static_cast<float>(q[4])),
                        stepU = cv::vx_setall_f32(static_cast<float>(1.0 - q[1]));
    const cv::v_float32 sixth = cv::vx_setall_f32(1.0f / 6.0f), half = cv::vx_setall_f32(0.5f),
                        three = cv::vx_setall_f32(3.0f), four = cv::vx_setall_f32(4.0f),
                        six = cv::vx_setall_f32(6.0f), oneHalf = cv::vx_setall_f32(1.5f),
                        two = cv::vx_setall_f32(2.0f);
    const cv::v_int32 firstColumn = cv::vx_setall_s32(1), lastColumn = cv::vx_setall_s32(right.cols - 3);
    // Every sum, lane by lane; the lanes are added at the end.
    cv::v_float32 xx = zero, xxu = zero, xxv = zero, xxuu = zero, xxuv = zero, xxvv = zero, xr1 = zero, xru = zero,
                  xrv = zero, x1 = zero, xu = zero, xv = zero, rr = zero, r1 = zero, xe = zero, xue = zero,
                  xve = zero, re = zero, e1 = zero, w1 = zero, squares = zero;
    for (int v = -r; v <= r; ++v) {
        const float* row = right.ptr<float>(y + v);
        const float* l = support.leftWindow.data() + (v + r) * stride;
        const float* weights = support.laneWeight.data() + (v + r) * stride;
        // The row's footprint starts at rowStart; its whole pixel is taken out in double, so that
        // the lanes work on fractions of a few pixels (a float holds 2 560 only to 2e-4 px).
        const double rowStart = x - q[0] - q[2] * v;
        const double rowBase = std::floor(rowStart);
        const cv::v_int32 base = cv::vx_setall_s32(static_cast<int>(rowBase));
        const cv::v_float32 fraction = cv::vx_setall_f32(static_cast<float>(rowStart - rowBase));
        // This row's sums of dx², dx·value, dx and dx·e, each alone and times u, and of dx²·u².
        cv::v_float32 a1 = zero, au = zero, auu = zero, b1 = zero, bu = zero, c1 = zero, cu = zero, d1 = zero,
                      du = zero;
        for (int k = 0; k < stride; k += kLanes) {
            const cv::v_float32 w = cv::vx_load(weights + k), u = cv::vx_load(rows.u.data() + k);
            const cv::v_float32 xr = cv::v_fma(u, stepU, fraction);
            const cv::v_int32 whole = cv::v_floor(xr);
            const cv::v_int32 i = base + whole;
            const cv::v_int32 weighs = cv::v_reinterpret_as_s32(w > zero);
            if (cv::v_check_any(weighs & ((i < firstColumn) | (i > lastColumn)))) return false;
            // Lanes that weigh nothing may lie outside the image: read them at its edge.
            const cv::v_int32 at = cv::v_min(cv::v_max(i, firstColumn), lastColumn) - firstColumn;
            const cv::v_float32 s0 = cv::v_lut(row, at), s1 = cv::v_lut(row + 1, at), s2 = cv::v_lut(row + 2, at),
                                s3 = cv::v_lut(row + 3, at);
            const cv::v_float32 t = xr - cv::v_cvt_f32(whole), o = one - t, t2 = t * t, t3 = t2 * t;
            const cv::v_float32 value =
                (o * o * o * s0 + (three * t3 - six * t2 + four) * s1 + (three * (t2 - t3 + t) + one) * s2 + t3 * s3) *
                sixth;
            const cv::v_float32 slope = (oneHalf * t2 - two * t) * s1 - half * o * o * s0 +
                                        (half + t - oneHalf * t2) * s2 + half * t2 * s3;
            const cv::v_float32 residual = cv::vx_load(l + k) - cv::v_fma(gain, value, offset);
            const cv::v_float32 e = w * residual;
            const cv::v_float32 dx = zero - gain * slope;
            const cv::v_float32 wdx = w * dx;
            const cv::v_float32 dxdx = wdx * dx, dxdxu = dxdx * u, wdxValue = wdx * value, dxe = dx * e;
            a1 += dxdx;
            au += dxdxu;
            auu = cv::v_fma(dxdxu, u, auu);
            b1 += wdxValue;
            bu = cv::v_fma(wdxValue, u, bu);
            c1 += wdx;
            cu = cv::v_fma(wdx, u, cu);
            d1 += dxe;
            du = cv::v_fma(dxe, u, du);
            const cv::v_float32 wValue = w * value;
            rr = cv::v_fma(wValue, value, rr);
            r1 += wValue;
            w1 += w;
            re = cv::v_fma(value, e, re);
            e1 += e;
            squares = cv::v_fma(e, residual, squares);
        }
        const cv::v_float32 fv = cv::vx_setall_f32(static_cast<float>(v));
        xx += a1;
        xxu += au;
        xxv = cv::v_fma(a1, fv, xxv);
        xxuu += auu;
        xxuv = cv::v_fma(au, fv, xxuv);
        xxvv = cv::v_fma(a1 * fv, fv, xxvv);
        xr1 += b1;
        xru += bu;
        xrv = cv::v_fma(b1, fv, xrv);
        x1 += c1;
        xu += cu;
        xv = cv::v_fma(c1, fv, xv);
        xe += d1;
        xue += du;
        xve = cv::v_fma(d1, fv, xve);
    }
    Sums m;
    m.xx = cv::v_reduce_sum(xx);
    m.xxu = cv::v_reduce_sum(xxu);
    m.xxv = cv::v_reduce_sum(xxv);
    m.xxuu = cv::v_reduce_sum(xxuu);
    m.xxuv = cv::v_reduce_sum(xxuv);
    m.xxvv = cv::v_reduce_sum(xxvv);
    m.xr1 = cv::v_reduce_sum(xr1);
    m.xru = cv::v_reduce_sum(xru);
    m.xrv = cv::v_reduce_sum(xrv);
    m.x1 = cv::v_reduce_sum(x1);
    m.xu = cv::v_reduce_sum(xu);
    m.xv = cv::v_reduce_sum(xv);
    m.rr = cv::v_reduce_sum(rr);
    m.r1 = cv::v_reduce_sum(r1);
    m.xe = cv::v_reduce_sum(xe);
    m.xue = cv::v_reduce_sum(xue);
    m.xve = cv::v_reduce_sum(xve);
    m.re = cv::v_reduce_sum(re);
    m.e1 = cv::v_reduce_sum(e1);
    m.w1 = cv::v_reduce_sum(w1);
    m.squares = cv::v_reduce_sum(squares);
    m.assemble(out);
    return true;
}

// The left eye's window at (x, y) in the fast kernels' layout (the padding reads 0 and weighs
// nothing).
void copyLeftWindow(const cv::Mat& left, int x, int y, int r, WindowSupport& support) {
    const LaneRows& rows = support.rows;
    support.leftWindow.assign(static_cast<std::size_t>(rows.side * rows.stride), 0.0f);
    for (int v = -r; v <= r; ++v) {
        const float* l = left.ptr<float>(y + v) + x - r;
        std::copy(l, l + rows.side, support.leftWindow.data() + (v + r) * rows.stride);
    }
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
    double inverse00 = 0;
    for (int iteration = 0; iteration < p.iterations; ++iteration) {
        if (!equationsAt(q, at)) return -1.0;  // the footprint left the image
        // JᵀWJ is positive definite wherever the window can tell anything: Cholesky, unpivoted.
        const Eigen::LLT<Matrix5> solver(at.h);
        if (solver.info() != Eigen::Success) return -1.0;
        inverse00 = solver.solve(Vector5::Unit(0))[0];
        if (hopeless(inverse00, at.squares, support.total, iteration, p)) return kGaveUp;
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
    // The disparity's variance: the residual's, through the inverse of the normal matrix at the
    // last step.
    const double variance = inverse00 * (at.squares / (support.total - 5));
    if (!(variance >= 0) || std::sqrt(variance) > p.maxSigmaPx) return -1.0;
    return q[0];
}

// The window at (x, y); `right` holds the right eye's spline coefficients.
double refinePixelReference(const cv::Mat& left, const cv::Mat& right, int x, int y, double start,
                            WindowSupport& support, const SlantedRefinement& p) {
    return fitWindow(start, support, p, [&](const Vector5& q, NormalEquations& out) {
        return normalEquationsReference(left, right, x, y, q, support, p.radius, out);
    });
}

double refinePixel(const cv::Mat& left, const cv::Mat& right, int x, int y, double start, WindowSupport& support,
                   const SlantedRefinement& p) {
    copyLeftWindow(left, x, y, p.radius, support);
    return fitWindow(start, support, p, [&](const Vector5& q, NormalEquations& out) {
        return normalEquations(right, x, y, q, support, p.radius, out);
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
