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
// The volume is swept three times: along rows (both horizontal directions, rows split over
// stripes), then down and up (three directions each, row after row, columns split over stripes).
// The recurrence runs 8 disparities per vector with saturating 16-bit arithmetic, fused with the
// minimum for the next step and the sum; padded lanes hold 0xFFFF and never win a minimum.
#include <algorithm>
#include <cmath>

#include "core/common/simd.hpp"

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

// One step of the recurrence for all disparities of a pixel, fused with the sum over directions
// (kFirst: the sum starts here). Returns min_d of the new L, the next step's min_t L(p-r, t).
template <bool kFirst>
std::uint16_t stepAndAccumulate(const std::uint16_t* cost, const std::uint16_t* previous, std::uint16_t minPrevious,
                                int stride, std::uint16_t p1, std::uint16_t p2, std::uint16_t* out,
                                std::uint16_t* sum) {
    const cv::v_uint16x8 vMin = cv::v_setall_u16(minPrevious);
    const cv::v_uint16x8 vJump = vMin + cv::v_setall_u16(p2);  // saturating
    const cv::v_uint16x8 vP1 = cv::v_setall_u16(p1);
    const cv::v_uint16x8 none = cv::v_setall_u16(0xFFFF);
    cv::v_uint16x8 newMin = none;
    cv::v_uint16x8 before = none;
    cv::v_uint16x8 current = cv::v_load(previous);
    for (int d = 0; d < stride; d += kLanes) {
        const cv::v_uint16x8 after = d + kLanes < stride ? cv::v_load(previous + d + kLanes) : none;
        const cv::v_uint16x8 lower = cv::v_extract<kLanes - 1>(before, current);  // L(d-1)
        const cv::v_uint16x8 upper = cv::v_extract<1>(current, after);            // L(d+1)
        cv::v_uint16x8 m = cv::v_min(current, cv::v_min(lower + vP1, upper + vP1));
        m = cv::v_min(m, vJump);
        const cv::v_uint16x8 l = cv::v_load(cost + d) + (m - vMin);
        cv::v_store(out + d, l);
        cv::v_store(sum + d, kFirst ? l : cv::v_load(sum + d) + l);
        newMin = cv::v_min(newMin, l);
        before = current;
        current = after;
    }
    return cv::v_reduce_min(newMin);
}

// The first pixel of a line: L = C.
template <bool kFirst>
std::uint16_t startLine(const std::uint16_t* cost, int stride, std::uint16_t* out, std::uint16_t* sum) {
    cv::v_uint16x8 newMin = cv::v_setall_u16(0xFFFF);
    for (int d = 0; d < stride; d += kLanes) {
        const cv::v_uint16x8 l = cv::v_load(cost + d);
        cv::v_store(out + d, l);
        cv::v_store(sum + d, kFirst ? l : cv::v_load(sum + d) + l);
        newMin = cv::v_min(newMin, l);
    }
    return cv::v_reduce_min(newMin);
}

int penaltyCaseAt(const cv::Mat& bgr, int x, int y, Direction r, int tau) {
    const int px = x - r.dx, py = y - r.dy, qx = px - r.dx, qy = py - r.dy;
    const int d1 = colourDistance(bgr.at<cv::Vec3b>(y, x), bgr.at<cv::Vec3b>(py, px));
    const bool hasSecond = qx >= 0 && qy >= 0 && qx < bgr.cols && qy < bgr.rows;
    const int d2 = hasSecond ? colourDistance(bgr.at<cv::Vec3b>(py, px), bgr.at<cv::Vec3b>(qy, qx)) : 0;
    return penaltyCase(d1, d2, tau);
}

// Left-to-right and right-to-left along every row: rows are independent, split over stripes.
// This pass starts the sum.
void horizontalPass(const CostVolume& costs, const cv::Mat& bgr, const ScanlinePenalties& penalties, CostVolume& sum) {
    const int width = costs.width, stride = costs.stride;
    forEachStripe(costs.height, [&](int, int begin, int end) {
        std::vector<std::uint16_t> buffers(static_cast<std::size_t>(2 * stride));
        std::uint16_t* previous = buffers.data();
        std::uint16_t* current = buffers.data() + stride;
        for (int y = begin; y < end; ++y) {
            std::uint16_t minimum = startLine<true>(costs.at(0, y), stride, previous, sum.at(0, y));
            for (int x = 1; x < width; ++x) {
                const int c = penaltyCaseAt(bgr, x, y, {1, 0}, penalties.tau);
                minimum = stepAndAccumulate<true>(costs.at(x, y), previous, minimum, stride, penalties.p1[c],
                                                  penalties.p2[c], current, sum.at(x, y));
                std::swap(previous, current);
            }
            minimum = startLine<false>(costs.at(width - 1, y), stride, previous, sum.at(width - 1, y));
            for (int x = width - 2; x >= 0; --x) {
                const int c = penaltyCaseAt(bgr, x, y, {-1, 0}, penalties.tau);
                minimum = stepAndAccumulate<false>(costs.at(x, y), previous, minimum, stride, penalties.p1[c],
                                                   penalties.p2[c], current, sum.at(x, y));
                std::swap(previous, current);
            }
        }
    });
}

// The three directions that go down (dy = 1) or up (dy = -1), row after row: each row depends
// only on the previous one, so a row's columns are split over stripes. One read of the costs and
// one update of the sum serve all three directions.
void verticalPass(const CostVolume& costs, const cv::Mat& bgr, const ScanlinePenalties& penalties, int dy,
                  CostVolume& sum) {
    const int width = costs.width, height = costs.height, stride = costs.stride;
    const Direction directions[3] = {{0, dy}, {1, dy}, {-1, dy}};
    const auto rowSize = static_cast<std::size_t>(width) * stride;
    std::vector<std::uint16_t> rows(6 * rowSize);  // previous and current row of L per direction
    std::vector<std::uint16_t> minima(6 * static_cast<std::size_t>(width));
    std::uint16_t* previous[3];
    std::uint16_t* current[3];
    std::uint16_t* previousMin[3];
    std::uint16_t* currentMin[3];
    for (int i = 0; i < 3; ++i) {
        previous[i] = rows.data() + (2 * i) * rowSize;
        current[i] = rows.data() + (2 * i + 1) * rowSize;
        previousMin[i] = minima.data() + (2 * i) * static_cast<std::size_t>(width);
        currentMin[i] = minima.data() + (2 * i + 1) * static_cast<std::size_t>(width);
    }
    for (int step = 0; step < height; ++step) {
        const int y = dy > 0 ? step : height - 1 - step;
        forEachStripe(width, [&](int, int begin, int end) {
            for (int x = begin; x < end; ++x) {
                for (int i = 0; i < 3; ++i) {
                    const Direction r = directions[i];
                    const int px = x - r.dx;
                    std::uint16_t* out = current[i] + static_cast<std::size_t>(x) * stride;
                    if (step == 0 || px < 0 || px >= width) {
                        currentMin[i][x] = startLine<false>(costs.at(x, y), stride, out, sum.at(x, y));
                    } else {
                        const int c = penaltyCaseAt(bgr, x, y, r, penalties.tau);
                        currentMin[i][x] = stepAndAccumulate<false>(
                            costs.at(x, y), previous[i] + static_cast<std::size_t>(px) * stride, previousMin[i][px],
                            stride, penalties.p1[c], penalties.p2[c], out, sum.at(x, y));
                    }
                }
            }
        });
        for (int i = 0; i < 3; ++i) {
            std::swap(previous[i], current[i]);
            std::swap(previousMin[i], currentMin[i]);
        }
    }
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
    // Three sweeps over the volume instead of eight.
    horizontalPass(costs, bgr, penalties, sum);
    verticalPass(costs, bgr, penalties, 1, sum);
    verticalPass(costs, bgr, penalties, -1, sum);
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
