#include "core/volume/slanted_refinement.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
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

// The matcher's disparities averaged over the valid pixels of a (2r+1)^2 box: the plane's start.
cv::Mat smoothedValid(const cv::Mat& disparity, int radius) {
    const cv::Mat valid = disparity >= 0;
    cv::Mat values, weights;
    disparity.copyTo(values);
    values.setTo(0, ~valid);
    valid.convertTo(weights, CV_32F, 1.0 / 255.0);
    const cv::Size box(2 * radius + 1, 2 * radius + 1);
    cv::boxFilter(values, values, CV_32F, box, {-1, -1}, false, cv::BORDER_CONSTANT);
    cv::boxFilter(weights, weights, CV_32F, box, {-1, -1}, false, cv::BORDER_CONSTANT);
    cv::Mat smoothed(disparity.size(), CV_32F, cv::Scalar(-1));
    // Only where most of the box was measured: a slope read across a hole is a guess.
    const float enough = 0.5f * static_cast<float>(box.area());
    for (int y = 0; y < disparity.rows; ++y) {
        const float* v = values.ptr<float>(y);
        const float* w = weights.ptr<float>(y);
        float* s = smoothed.ptr<float>(y);
        for (int x = 0; x < disparity.cols; ++x) {
            if (w[x] >= enough) s[x] = v[x] / w[x];
        }
    }
    return smoothed;
}

// The plane's slopes at (x, y) from the smoothed disparities a window's radius either side; 0
// where a side is not known.
cv::Vec2d startSlopes(const cv::Mat& smoothed, int x, int y, int radius) {
    auto at = [&](int xx, int yy) {
        if (xx < 0 || yy < 0 || xx >= smoothed.cols || yy >= smoothed.rows) return -1.0f;
        return smoothed.at<float>(yy, xx);
    };
    const float left = at(x - radius, y), right = at(x + radius, y);
    const float up = at(x, y - radius), down = at(x, y + radius);
    const double a = left >= 0 && right >= 0 ? (right - left) / (2.0 * radius) : 0.0;
    const double b = up >= 0 && down >= 0 ? (down - up) / (2.0 * radius) : 0.0;
    return {a, b};
}

// One pixel's window, from the matcher's value `start` and the plane's `slopes`; `right` holds the
// right eye's spline coefficients. Returns the refined disparity, or a negative value where the
// matcher's stands.
double refinePixel(const cv::Mat& left, const cv::Mat& right, int x, int y, double start, cv::Vec2d slopes,
                   const SlantedRefinement& p) {
    const int r = p.radius;
    const int samples = (2 * r + 1) * (2 * r + 1);
    // Parameters: disparity, its slopes along x and y, the right eye's gain and offset.
    Vector5 q;
    q << start, slopes[0], slopes[1], 1.0, 0.0;
    bool converged = false;
    Matrix5 h;
    double squares = 0;
    for (int iteration = 0; iteration < p.iterations; ++iteration) {
        // The normal equations' sums written out: J = (dx, dx·u, dx·v, value, 1), dx the model's
        // derivative along the disparity.
        double xx = 0, xxu = 0, xxv = 0, xxuu = 0, xxuv = 0, xxvv = 0;
        double xr1 = 0, xru = 0, xrv = 0, x1 = 0, xu = 0, xv = 0, rr = 0, r1 = 0;
        double xe = 0, xue = 0, xve = 0, re = 0, e1 = 0;
        squares = 0;
        for (int v = -r; v <= r; ++v) {
            const float* l = left.ptr<float>(y + v);
            const float* row = right.ptr<float>(y + v);
            const double rowStart = x - q[0] - q[2] * v;
            for (int u = -r; u <= r; ++u) {
                const double xr = rowStart + u * (1.0 - q[1]);
                const double base = std::floor(xr);
                const int i = static_cast<int>(base);
                if (i < 1 || i + 2 >= right.cols) return -1.0;  // the footprint left the image
                const Cubic c(xr - base);
                const float* s = row + i - 1;
                const double value = c.value[0] * s[0] + c.value[1] * s[1] + c.value[2] * s[2] + c.value[3] * s[3];
                const double slope = c.slope[0] * s[0] + c.slope[1] * s[1] + c.slope[2] * s[2] + c.slope[3] * s[3];
                // model m = gain · R(xr) + offset; xr falls as the disparity rises.
                const double e = l[x + u] - (q[3] * value + q[4]);
                const double dx = -q[3] * slope;
                const double dxdx = dx * dx;
                xx += dxdx;
                xxu += dxdx * u;
                xxv += dxdx * v;
                xxuu += dxdx * u * u;
                xxuv += dxdx * u * v;
                xxvv += dxdx * v * v;
                xr1 += dx * value;
                xru += dx * value * u;
                xrv += dx * value * v;
                x1 += dx;
                xu += dx * u;
                xv += dx * v;
                rr += value * value;
                r1 += value;
                xe += dx * e;
                xue += dx * u * e;
                xve += dx * v * e;
                re += value * e;
                e1 += e;
                squares += e * e;
            }
        }
        h << xx, xxu, xxv, xr1, x1,
             xxu, xxuu, xxuv, xru, xu,
             xxv, xxuv, xxvv, xrv, xv,
             xr1, xru, xrv, rr, r1,
             x1, xu, xv, r1, static_cast<double>(samples);
        Vector5 g;
        g << xe, xue, xve, re, e1;
        const Eigen::LDLT<Matrix5> solver(h);
        if (solver.info() != Eigen::Success) return -1.0;
        const Vector5 step = solver.solve(g);
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
    const Matrix5 covariance = h.inverse() * (squares / (samples - 5));
    if (!(covariance(0, 0) >= 0) || std::sqrt(covariance(0, 0)) > p.maxSigmaPx) return -1.0;
    return q[0];
}

}  // namespace

SlantedRefinementCount refineSlanted(const cv::Mat& left, const cv::Mat& right, const cv::Rect& area,
                                     const SlantedRefinement& parameters, cv::Mat& disparity) {
    CV_Assert(left.type() == CV_32FC1 && right.type() == CV_32FC1 && disparity.type() == CV_32FC1);
    CV_Assert(left.size() == right.size() && left.size() == disparity.size() && parameters.radius >= 1);
    const int r = parameters.radius;
    const cv::Rect inside = area & cv::Rect(r, r, left.cols - 2 * r, left.rows - 2 * r);
    if (inside.empty()) return {};
    const cv::Mat matched = disparity.clone();
    const cv::Mat rightSpline = splineCoefficients(right);
    const cv::Mat smoothed = smoothedValid(matched, r);
    std::array<int, kFixedBands> refined{}, kept{};
    forEachFixedBand(static_cast<std::size_t>(inside.height), [&](int band, std::size_t begin, std::size_t end) {
        for (auto row = begin; row < end; ++row) {
            const int y = inside.y + static_cast<int>(row);
            const float* m = matched.ptr<float>(y);
            float* out = disparity.ptr<float>(y);
            for (int x = inside.x; x < inside.x + inside.width; ++x) {
                if (m[x] < 0) continue;
                const double d = refinePixel(left, rightSpline, x, y, m[x], startSlopes(smoothed, x, y, r), parameters);
                if (d >= 0) {
                    out[x] = static_cast<float>(d);
                    ++refined[static_cast<std::size_t>(band)];
                } else {
                    ++kept[static_cast<std::size_t>(band)];
                }
            }
        }
    });
    SlantedRefinementCount count;
    for (int b = 0; b < kFixedBands; ++b) {
        count.refined += refined[static_cast<std::size_t>(b)];
        count.kept += kept[static_cast<std::size_t>(b)];
    }
    return count;
}

}  // namespace icewatch::volume
