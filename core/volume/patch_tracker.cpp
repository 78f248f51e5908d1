// Patch tracking between two captures or two eyes: integer search by zero-mean normalised
// correlation, then a symmetric sub-pixel refinement with a gain and an offset (patch_tracker.hpp).
#include "core/volume/patch_tracker.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include <opencv2/imgproc.hpp>

namespace icewatch::volume {

namespace {

// Sub-pixel resampling by cubic B-spline interpolation (Unser, "Splines: a perfect fit for signal
// and image processing", 1999): the samples are first turned into B-spline coefficients by the
// exact recursive prefilter, so the interpolant passes through every sample, and its phase error on
// the smoothed images the trackers read stays below a thousandth of a pixel. A cubic convolution
// kernel (Keys) left a bias of ±0.006 px that depended on the fraction of the shift; all patches
// of a capture share that fraction, so the bias did not average out and tilted the registration.
constexpr double kSplinePole = -0.2679491924311228;  // √3 - 2
// The recursive prefilter's influence falls as |pole|^k: beyond this many samples it is below 1e-7
// of a grey level, so the window's mirrored edges do not reach a sample taken this far inside.
constexpr int kSplineMargin = 12;

// In place: samples -> cubic B-spline coefficients along one line (mirror boundaries).
void splineCoefficients(double* line, int n) {
    if (n < 2) return;
    const double z = kSplinePole;
    double sum = line[0], power = z;
    for (int k = 1; k < std::min(n, 2 * kSplineMargin); ++k, power *= z) sum += power * line[k];
    line[0] = sum;
    for (int k = 1; k < n; ++k) line[k] += z * line[k - 1];
    line[n - 1] = (z / (z * z - 1.0)) * (line[n - 1] + z * line[n - 2]);
    for (int k = n - 2; k >= 0; --k) line[k] = z * (line[k + 1] - line[k]);
    for (int k = 0; k < n; ++k) line[k] *= 6.0;
}

// The coefficients of the whole image, rows then columns (the spline is separable), in double
// precision; fixed bands of lines, so the result does not depend on the number of threads.
cv::Mat splineCoefficientImage(const cv::Mat& grey) {
    cv::Mat c;
    grey.convertTo(c, CV_64F);
    cv::parallel_for_(cv::Range(0, c.rows), [&](const cv::Range& rows) {
        for (int y = rows.start; y < rows.end; ++y) splineCoefficients(c.ptr<double>(y), c.cols);
    });
    cv::parallel_for_(cv::Range(0, c.cols), [&](const cv::Range& cols) {
        std::vector<double> line(static_cast<std::size_t>(c.rows));
        for (int x = cols.start; x < cols.end; ++x) {
            for (int y = 0; y < c.rows; ++y) line[static_cast<std::size_t>(y)] = c.at<double>(y, x);
            splineCoefficients(line.data(), c.rows);
            for (int y = 0; y < c.rows; ++y) c.at<double>(y, x) = line[static_cast<std::size_t>(y)];
        }
    });
    cv::Mat out;
    c.convertTo(out, CV_32F);
    return out;
}

// Cubic B-spline weights for the taps at -1, 0, 1, 2 of a fraction t in [0, 1).
std::array<double, 4> splineWeights(double t) {
    const double s = 1.0 - t, t2 = t * t, t3 = t2 * t;
    return {s * s * s / 6.0, (4.0 - 6.0 * t2 + 3.0 * t3) / 6.0, (1.0 + 3.0 * t + 3.0 * t2 - 3.0 * t3) / 6.0, t3 / 6.0};
}

// The (2h+1)² samples of `image` around the real frame position `centre`, every sample shifted by
// the same fraction, so the spline is separable with one set of weights. False where a tap comes
// within the prefilter's margin of the window's edge.
bool samplePatch(const TrackingImage& image, cv::Point2d centre, int h, std::vector<double>& out) {
    const cv::Point2d local = centre - cv::Point2d(image.origin);
    const double fx = std::floor(local.x), fy = std::floor(local.y);
    const int ix = static_cast<int>(fx), iy = static_cast<int>(fy);
    const int m = kSplineMargin, x0 = ix - h - 1, y0 = iy - h - 1, side = 2 * h + 1;
    if (x0 < m || y0 < m || x0 + side + 3 + m > image.spline.cols || y0 + side + 3 + m > image.spline.rows) return false;
    const auto wx = splineWeights(local.x - fx), wy = splineWeights(local.y - fy);
    thread_local std::vector<double> rows;
    rows.resize(static_cast<std::size_t>(side + 3) * side);
    for (int r = 0; r < side + 3; ++r) {
        const float* row = image.spline.ptr<float>(y0 + r) + x0;
        double* to = rows.data() + static_cast<std::size_t>(r) * side;
        for (int col = 0; col < side; ++col) {
            const float* p = row + col;
            to[col] = wx[0] * p[0] + wx[1] * p[1] + wx[2] * p[2] + wx[3] * p[3];
        }
    }
    out.resize(static_cast<std::size_t>(side) * side);
    for (int r = 0; r < side; ++r)
        for (int col = 0; col < side; ++col) {
            const auto at = [&](int k) { return rows[static_cast<std::size_t>(r + k) * side + col]; };
            out[static_cast<std::size_t>(r) * side + col] = wy[0] * at(0) + wy[1] * at(1) + wy[2] * at(2) + wy[3] * at(3);
        }
    return true;
}

// Vertex of the parabola through three scores, as an offset in (-1, 1).
double parabolaPeak(double minus, double centre, double plus) {
    const double curvature = minus - 2.0 * centre + plus;
    if (curvature >= 0) return 0.0;
    return std::clamp(0.5 * (minus - plus) / curvature, -0.5, 0.5);
}

struct IntegerMatch {
    bool found = false;
    cv::Point shift;
    cv::Point2d subpixel;
};

IntegerMatch integerSearch(const TrackingImage& from, const TrackingImage& to, cv::Point at, cv::Point2d prior,
                           const PatchTrackOptions& o) {
    const int r = o.radiusPx, sx = o.searchPx, sy = o.horizontalOnly ? 0 : o.searchPx;
    const cv::Point centre(at.x + static_cast<int>(std::lround(prior.x)), at.y + static_cast<int>(std::lround(prior.y)));
    const cv::Rect templ(at.x - r, at.y - r, 2 * r + 1, 2 * r + 1);
    const cv::Rect area(centre.x - r - sx, centre.y - r - sy, 2 * (r + sx) + 1, 2 * (r + sy) + 1);
    const cv::Rect fromBounds = from.frameRect(), toBounds = to.frameRect();
    if ((templ & fromBounds) != templ || (area & toBounds) != area) return {};
    cv::Mat scores;
    cv::matchTemplate(to.grey(area - to.origin), from.grey(templ - from.origin), scores, cv::TM_CCOEFF_NORMED);
    cv::Point best;
    cv::minMaxLoc(scores, nullptr, nullptr, nullptr, &best);
    // A peak on the edge of the search area may be the slope of one outside it.
    if (best.x == 0 || best.x == scores.cols - 1) return {};
    if (!o.horizontalOnly && (best.y == 0 || best.y == scores.rows - 1)) return {};
    IntegerMatch m;
    m.found = true;
    m.shift = centre + best - cv::Point(sx, sy) - at;
    m.subpixel.x = parabolaPeak(scores.at<float>(best.y, best.x - 1), scores.at<float>(best), scores.at<float>(best.y, best.x + 1));
    if (!o.horizontalOnly) {
        m.subpixel.y = parabolaPeak(scores.at<float>(best.y - 1, best.x), scores.at<float>(best), scores.at<float>(best.y + 1, best.x));
    }
    return m;
}

}  // namespace

TrackingImage prepareForTracking(const cv::Mat& grey, cv::Point origin) {
    TrackingImage image;
    cv::Mat f;
    grey.convertTo(f, CV_32F);
    cv::GaussianBlur(f, image.grey, {0, 0}, kTrackingSmoothingPx, kTrackingSmoothingPx, cv::BORDER_REFLECT);
    image.spline = splineCoefficientImage(image.grey);
    image.origin = origin;
    return image;
}

double splineValueAt(const TrackingImage& image, cv::Point2d at) {
    std::vector<double> one;
    if (!samplePatch(image, at, 0, one)) return std::numeric_limits<double>::quiet_NaN();
    return one.front();
}

namespace {

// The symmetric sub-pixel refinement from the integer match, starting `initial` px from its
// integer shift, the patches sampled on the pixel grid moved by `grid` (a fraction of a pixel).
PatchTrack refine(const TrackingImage& from, const TrackingImage& to, cv::Point at, const IntegerMatch& start,
                  cv::Point2d initial, const PatchTrackOptions& o, cv::Point2d grid) {
    PatchTrack track;
    cv::Point whole = start.shift;
    cv::Point2d delta = initial;
    const int r = o.radiusPx, side = 2 * r + 1, n = side * side;
    // to ≈ (gain + ramp·(u, v))·from + offset: the gain may change across the patch, as shading
    // does when the surface turns against the light; a ramp left out of the model correlates with
    // the texture's gradient and moves the shift (a few thousandths of a pixel per percent of
    // gain change across 100 px, systematically, the same for every patch).
    constexpr int kUnknowns = 6;  // δx δy gain offset ramp-u ramp-v (δy held in horizontal tracks)
    std::vector<double> f, t;
    double gain = 1, offset = 0;
    cv::Vec2d ramp(0, 0);
    cv::Matx<double, kUnknowns, kUnknowns> normal;
    double residualVariance = 0;
    bool converged = false;
    for (int iteration = 0; iteration < o.iterations && !converged; ++iteration) {
        // Re-centre the integer part once a resampling would go beyond three quarters of a pixel
        // (not at a half: a shift near it would flip between the two sides).
        auto whole1 = [](double v) { return std::abs(v) > 0.75 ? static_cast<int>(std::lround(v)) : 0; };
        const cv::Point step(whole1(delta.x), whole1(delta.y));
        whole += step;
        delta -= cv::Point2d(step);
        if (std::abs(whole.x - start.shift.x) > 2 || std::abs(whole.y - start.shift.y) > 2) return track;
        if (!samplePatch(from, cv::Point2d(at) + grid - 0.5 * delta, r + 1, f) ||
            !samplePatch(to, cv::Point2d(at + whole) + grid + 0.5 * delta, r + 1, t)) {
            return track;
        }
        const int big = side + 2;
        if (iteration == 0) {  // the photometric start: the regression of to on from
            double sf = 0, st = 0, sff = 0, sft = 0;
            for (int y = 1; y <= side; ++y)
                for (int x = 1; x <= side; ++x) {
                    const double a = f[static_cast<std::size_t>(y) * big + x], b = t[static_cast<std::size_t>(y) * big + x];
                    sf += a, st += b, sff += a * a, sft += a * b;
                }
            const double varF = sff - sf * sf / n;
            if (varF <= 1e-9) return track;
            gain = (sft - sf * st / n) / varF;
            offset = (st - gain * sf) / n;
        }
        // Sums in local arrays the unrolled loops keep in registers: accumulated in the matrix
        // itself, every term was a load and a store through memory (half the tracker's time).
        // The same products in the same order, so the same sums.
        double upper[kUnknowns][kUnknowns] = {};
        double rhsSum[kUnknowns] = {};
        double sse = 0;
        for (int y = 1; y <= side; ++y)
            for (int x = 1; x <= side; ++x) {
                const auto at2 = [&](const std::vector<double>& v, int dx, int dy) {
                    return v[static_cast<std::size_t>(y + dy) * big + x + dx];
                };
                const double u = double(x - 1 - r) / r, v = double(y - 1 - r) / r;
                const double localGain = gain + ramp[0] * u + ramp[1] * v;
                const double a = at2(f, 0, 0), b = at2(t, 0, 0);
                const double e = b - (localGain * a + offset);
                // e(δ) = to(x + δ/2) - gain(x)·from(x - δ/2) - offset: both halves move with δ.
                const double jx = 0.25 * ((at2(t, 1, 0) - at2(t, -1, 0)) + localGain * (at2(f, 1, 0) - at2(f, -1, 0)));
                const double jy = 0.25 * ((at2(t, 0, 1) - at2(t, 0, -1)) + localGain * (at2(f, 0, 1) - at2(f, 0, -1)));
                const double row[kUnknowns] = {jx, o.horizontalOnly ? 0.0 : jy, -a, -1.0, -a * u, -a * v};
#pragma GCC unroll 6
                for (int i = 0; i < kUnknowns; ++i) {
                    rhsSum[i] -= row[i] * e;
#pragma GCC unroll 6
                    for (int j = i; j < kUnknowns; ++j) upper[i][j] += row[i] * row[j];
                }
                sse += e * e;
            }
        cv::Vec<double, kUnknowns> rhs;
        for (int i = 0; i < kUnknowns; ++i) {
            rhs[i] = rhsSum[i];
            for (int j = i; j < kUnknowns; ++j) normal(i, j) = normal(j, i) = upper[i][j];
        }
        if (o.horizontalOnly) normal(1, 1) = 1;
        cv::Vec<double, kUnknowns> update;
        if (!cv::solve(normal, rhs, update, cv::DECOMP_CHOLESKY)) return track;
        delta.x += update[0];
        if (!o.horizontalOnly) delta.y += update[1];
        gain += update[2];
        offset += update[3];
        ramp += cv::Vec2d(update[4], update[5]);
        residualVariance = sse / std::max(1, n - (o.horizontalOnly ? kUnknowns - 1 : kUnknowns));
        converged = std::hypot(update[0], o.horizontalOnly ? 0.0 : update[1]) < o.convergedPx;
    }
    if (!converged) return track;
    // Statistics of the aligned patches.
    double sf = 0, st = 0, sff = 0, stt = 0, sft = 0;
    const int big = side + 2;
    for (int y = 1; y <= side; ++y)
        for (int x = 1; x <= side; ++x) {
            const double a = f[static_cast<std::size_t>(y) * big + x], b = t[static_cast<std::size_t>(y) * big + x];
            sf += a, st += b, sff += a * a, stt += b * b, sft += a * b;
        }
    const double varF = sff - sf * sf / n, varT = stt - st * st / n, cov = sft - sf * st / n;
    track.zncc = varF > 0 && varT > 0 ? cov / std::sqrt(varF * varT) : 0.0;
    track.textureSigma = std::sqrt(std::max(0.0, varF / n));
    track.meanFrom = sf / n;
    track.brightnessRatio = sf > 0 ? st / sf : 0.0;
    // Gain and offset reported from the spreads (reduced major axis), not the regression above:
    // noise in `from` dilutes a regression's slope on weak texture, and the lost slope would read
    // as an offset that is not there.
    const double r2 = varF > 0 && varT > 0 ? cov * cov / (varF * varT) : 0.0;
    track.gain = varF > 0 ? std::copysign(std::sqrt(varT / varF), cov) : 0.0;
    track.offset = (st - track.gain * sf) / n;
    // Neighbouring pixels of a resampled patch are not independent: count a quarter of them.
    const double gainSigma = std::abs(track.gain) * std::sqrt(std::max(0.0, 1.0 - r2) / std::max(1.0, n / 4.0));
    track.residualSigma = std::sqrt(residualVariance);
    const cv::Matx<double, kUnknowns, kUnknowns> covariance = normal.inv(cv::DECOMP_CHOLESKY) * residualVariance;
    if (o.horizontalOnly) {
        track.covariance = cv::Matx22d(covariance(0, 0), 0, 0, 0);
    } else {
        track.covariance = cv::Matx22d(covariance(0, 0), covariance(0, 1), covariance(1, 0), covariance(1, 1));
    }
    track.offsetSigma = gainSigma * std::abs(sf / n);
    track.shift = cv::Point2d(whole) + delta;
    track.found = true;
    return track;
}

}  // namespace

PatchTrack trackPatch(const TrackingImage& from, const TrackingImage& to, cv::Point at, cv::Point2d prior,
                      const PatchTrackOptions& o) {
    CV_Assert(from.grey.type() == CV_32FC1 && to.grey.type() == CV_32FC1);
    const IntegerMatch start = integerSearch(from, to, at, prior, o);
    if (!start.found) return {};
    // The interpolator's error is periodic in the fraction of a pixel at which it samples, odd
    // about the half, and its main part changes sign half a pixel on. Every patch of an object
    // that moved without turning shares that fraction, so the error does not average out over the
    // patches (on fine texture, up to 0.003 px at 0.7 px smoothing): the shift refined on the
    // pixel grid and on the grid moved by half a pixel, averaged, cancels it.
    PatchTrack track = refine(from, to, at, start, start.subpixel, o, {0.0, 0.0});
    if (!track.found) return track;
    // The second refinement starts where the first ended: a step or two.
    const PatchTrack shifted = refine(from, to, at, start, track.shift - cv::Point2d(start.shift), o,
                                      {0.5, o.horizontalOnly ? 0.0 : 0.5});
    if (!shifted.found) return {};
    track.shift = 0.5 * (track.shift + shifted.shift);
    return track;
}

}  // namespace icewatch::volume
