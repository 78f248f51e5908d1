// Scanline optimisation along 8 directions (Hirschmüller's semi-global recurrence with the
// colour-adaptive penalties of Mei et al.; the seed paper's variant):
//   L_r(p,d) = C(p,d) + min(L_r(p-r,d), L_r(p-r,d±1) + P1, min_t L_r(p-r,t) + P2) - min_t L_r(p-r,t)
// with (P1, P2) = (Π1, Π2) when both D1 = D_c(p, p-r) and D2 = D_c(p-r, p-2r) are below τ_SO,
// (Π1/4, Π2/4) when exactly one is, (Π1/10, Π2/10) when neither is: a colour edge makes a
// disparity jump cheap. (Mei takes D2 in the right image at p-d; the seed paper, followed here and
// for both methods, takes both differences in the left image, which keeps the penalties the same
// for every disparity of a pixel.) The directions are summed; the WTA of the sum equals that of
// the paper's mean.
//
// Each direction is a set of independent lines (rows, columns or diagonals); the lines are split
// into fixed stripes over threads. The recurrence runs 8 disparities per vector with saturating
// 16-bit arithmetic; padded lanes hold 0xFFFF and never win a minimum.
#include <algorithm>
#include <cmath>

#include <opencv2/core/hal/intrin.hpp>

#include "core/stereo/stages.hpp"

namespace icewatch::stereo::detail {

namespace {

constexpr int kLanes = cv::v_uint16x8::nlanes;

std::uint16_t saturatedAdd(int a, int b) { return static_cast<std::uint16_t>(std::min(a + b, 0xFFFF)); }

std::uint16_t fixedPoint(double value) {
    return static_cast<std::uint16_t>(std::lround(value * kCostScale));
}

struct Direction {
    int dx, dy;
};
constexpr Direction kDirections[8] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}, {1, 1}, {-1, -1}, {1, -1}, {-1, 1}};

// First pixels of every line of a direction: those whose predecessor p - r is outside the image.
std::vector<cv::Point> lineStarts(int width, int height, Direction r) {
    std::vector<cv::Point> starts;
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const int px = x - r.dx, py = y - r.dy;
            if (px < 0 || py < 0 || px >= width || py >= height) starts.emplace_back(x, y);
        }
    return starts;
}

std::uint16_t minimumOf(const std::uint16_t* values, int count) {
    cv::v_uint16x8 m = cv::v_load(values);
    for (int d = kLanes; d < count; d += kLanes) m = cv::v_min(m, cv::v_load(values + d));
    return cv::v_reduce_min(m);
}

void scanlineStepVector(const std::uint16_t* cost, const std::uint16_t* previous, int stride, std::uint16_t p1,
                        std::uint16_t p2, std::uint16_t* out) {
    const std::uint16_t minPrevious = minimumOf(previous, stride);
    const cv::v_uint16x8 vMin = cv::v_setall_u16(minPrevious);
    const cv::v_uint16x8 vJump = vMin + cv::v_setall_u16(p2);  // saturating
    const cv::v_uint16x8 vP1 = cv::v_setall_u16(p1);
    const cv::v_uint16x8 none = cv::v_setall_u16(0xFFFF);
    cv::v_uint16x8 before = none;
    cv::v_uint16x8 current = cv::v_load(previous);
    for (int d = 0; d < stride; d += kLanes) {
        const cv::v_uint16x8 after = d + kLanes < stride ? cv::v_load(previous + d + kLanes) : none;
        const cv::v_uint16x8 lower = cv::v_extract<kLanes - 1>(before, current);  // L(d-1)
        const cv::v_uint16x8 upper = cv::v_extract<1>(current, after);            // L(d+1)
        cv::v_uint16x8 m = cv::v_min(current, cv::v_min(lower + vP1, upper + vP1));
        m = cv::v_min(m, vJump);
        cv::v_store(out + d, cv::v_load(cost + d) + (m - vMin));
        before = current;
        current = after;
    }
}

template <bool kFirst>
void accumulate(std::uint16_t* sum, const std::uint16_t* l, int stride) {
    for (int d = 0; d < stride; d += kLanes) {
        cv::v_store(sum + d, kFirst ? cv::v_load(l + d) : cv::v_load(sum + d) + cv::v_load(l + d));
    }
}

template <bool kFirst>
void runDirection(const CostVolume& costs, const cv::Mat& bgr, const ScanlinePenalties& penalties, Direction r,
                  CostVolume& sum) {
    const std::vector<cv::Point> starts = lineStarts(costs.width, costs.height, r);
    const int stride = costs.stride;
    forEachStripe(static_cast<int>(starts.size()), [&](int, int begin, int end) {
        std::vector<std::uint16_t> bufferA(static_cast<std::size_t>(stride)), bufferB(static_cast<std::size_t>(stride));
        for (int i = begin; i < end; ++i) {
            int x = starts[static_cast<std::size_t>(i)].x, y = starts[static_cast<std::size_t>(i)].y;
            std::uint16_t* previous = bufferA.data();
            std::uint16_t* current = bufferB.data();
            std::copy(costs.at(x, y), costs.at(x, y) + stride, previous);
            accumulate<kFirst>(sum.at(x, y), previous, stride);
            int d1 = 0;  // D_c of the previous step, which becomes this step's D2
            for (int step = 1;; ++step) {
                const int nx = x + r.dx, ny = y + r.dy;
                if (nx < 0 || ny < 0 || nx >= costs.width || ny >= costs.height) break;
                const int d2 = step == 1 ? 0 : d1;
                d1 = colourDistance(bgr.at<cv::Vec3b>(ny, nx), bgr.at<cv::Vec3b>(y, x));
                const int c = penaltyCase(d1, d2, penalties.tau);
                scanlineStepVector(costs.at(nx, ny), previous, stride, penalties.p1[c], penalties.p2[c], current);
                accumulate<kFirst>(sum.at(nx, ny), current, stride);
                std::swap(previous, current);
                x = nx;
                y = ny;
            }
        }
    });
}

}  // namespace

ScanlinePenalties scanlinePenalties(const Parameters& parameters) {
    ScanlinePenalties p;
    const double divisors[3] = {1.0, 4.0, 10.0};
    for (int c = 0; c < 3; ++c) {
        p.p1[c] = fixedPoint(parameters.scanlinePi1 / divisors[c]);
        p.p2[c] = fixedPoint(parameters.scanlinePi2 / divisors[c]);
    }
    p.tau = parameters.scanlineTau;
    return p;
}

int penaltyCase(int d1, int d2, int tau) {
    const int below = (d1 < tau) + (d2 < tau);
    return 2 - below;  // both below: 0 (Π), one: 1 (Π/4), none: 2 (Π/10)
}

void scanlineStep(const std::uint16_t* cost, const std::uint16_t* previous, int disparities, std::uint16_t p1,
                  std::uint16_t p2, std::uint16_t* out) {
    int minPrevious = 0xFFFF;
    for (int t = 0; t < disparities; ++t) minPrevious = std::min<int>(minPrevious, previous[t]);
    for (int d = 0; d < disparities; ++d) {
        int m = previous[d];
        if (d > 0) m = std::min<int>(m, saturatedAdd(previous[d - 1], p1));
        if (d + 1 < disparities) m = std::min<int>(m, saturatedAdd(previous[d + 1], p1));
        m = std::min<int>(m, saturatedAdd(minPrevious, p2));
        out[d] = saturatedAdd(cost[d], m - minPrevious);
    }
}

void aggregateScanlines(const CostVolume& costs, const cv::Mat& bgr, const ScanlinePenalties& penalties,
                        CostVolume& sum) {
    sum.create(costs.width, costs.height, costs.disparities);
    runDirection<true>(costs, bgr, penalties, kDirections[0], sum);
    for (int i = 1; i < 8; ++i) runDirection<false>(costs, bgr, penalties, kDirections[i], sum);
}

void aggregateScanlinesReference(const CostVolume& costs, const cv::Mat& bgr, const ScanlinePenalties& penalties,
                                 CostVolume& sum) {
    sum.create(costs.width, costs.height, costs.disparities);
    std::fill(sum.data.begin(), sum.data.end(), 0);
    const int stride = costs.stride;
    CostVolume l;
    l.create(costs.width, costs.height, costs.disparities);
    for (const Direction r : kDirections) {
        // Visit pixels in an order where p - r always comes before p.
        const int y0 = r.dy >= 0 ? 0 : costs.height - 1, y1 = r.dy >= 0 ? costs.height : -1, sy = r.dy >= 0 ? 1 : -1;
        const int x0 = r.dx >= 0 ? 0 : costs.width - 1, x1 = r.dx >= 0 ? costs.width : -1, sx = r.dx >= 0 ? 1 : -1;
        for (int y = y0; y != y1; y += sy)
            for (int x = x0; x != x1; x += sx) {
                const int px = x - r.dx, py = y - r.dy;
                if (px < 0 || py < 0 || px >= costs.width || py >= costs.height) {
                    std::copy(costs.at(x, y), costs.at(x, y) + stride, l.at(x, y));
                } else {
                    const int qx = px - r.dx, qy = py - r.dy;
                    const bool hasSecond = qx >= 0 && qy >= 0 && qx < costs.width && qy < costs.height;
                    const int d1 = colourDistance(bgr.at<cv::Vec3b>(y, x), bgr.at<cv::Vec3b>(py, px));
                    const int d2 = hasSecond ? colourDistance(bgr.at<cv::Vec3b>(py, px), bgr.at<cv::Vec3b>(qy, qx)) : 0;
                    const int c = penaltyCase(d1, d2, penalties.tau);
                    scanlineStep(costs.at(x, y), l.at(px, py), stride, penalties.p1[c], penalties.p2[c], l.at(x, y));
                }
                for (int d = 0; d < stride; ++d) sum.at(x, y)[d] = saturatedAdd(sum.at(x, y)[d], l.at(x, y)[d]);
            }
    }
}

}  // namespace icewatch::stereo::detail
