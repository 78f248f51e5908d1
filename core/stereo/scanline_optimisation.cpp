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
// With the 4 axis directions only (the right view's pass), down and up run column by column with
// no wait between rows. The penalty case of every pixel and direction is computed once before the
// sweeps. The recurrence runs a whole vector of disparities at a time (8 or 16) with saturating
// 16-bit arithmetic, fused with the minimum for the next step and the sum; padded lanes hold
// 0xFFFF and never win a minimum.
#include <algorithm>
#include <cmath>
#include <type_traits>

#include "core/common/simd.hpp"

#include "core/stereo/stages.hpp"

namespace icewatch::stereo::detail {

namespace {

constexpr int kLanes = cv::v_uint16::nlanes;
constexpr int kLanes8 = cv::v_uint8x16::nlanes;
static_assert(kDisparityAlign % kLanes == 0, "whole vectors along the padded disparity axis");

std::uint16_t saturatedAdd(int a, int b) { return static_cast<std::uint16_t>(std::min(a + b, 0xFFFF)); }

std::uint16_t fixedPoint(double value) {
    return static_cast<std::uint16_t>(std::lround(value * kCostScale));
}

struct Direction {
    int dx, dy;
};
constexpr Direction kDirections[8] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}, {1, 1}, {-1, -1}, {1, -1}, {-1, 1}};

// One step of the recurrence for all disparities of a pixel, fused with the sum over directions
// (kFirst: the sum starts here; extra, when not null, is added to the sum as well). Returns min_d
// of the new L, the next step's min_t L(p-r, t).
// previous[-1] and previous[stride] must be readable and hold 0xFFFF (the guards of LineBuffers):
// L(d-1) and L(d+1) are then plain unaligned loads, not lane shuffles, which on AVX2 cross the
// two 128-bit halves and were the recurrence's bottleneck.
template <bool kFirst, bool kExtra = false>
std::uint16_t stepAndAccumulate(const std::uint16_t* cost, const std::uint16_t* previous, std::uint16_t minPrevious,
                                int stride, std::uint16_t p1, std::uint16_t p2, std::uint16_t* out,
                                std::uint16_t* sum, const std::uint16_t* extra = nullptr) {
    const cv::v_uint16 vMin = cv::vx_setall_u16(minPrevious);
    const cv::v_uint16 vJump = vMin + cv::vx_setall_u16(p2);  // saturating
    const cv::v_uint16 vP1 = cv::vx_setall_u16(p1);
    cv::v_uint16 newMin = cv::vx_setall_u16(0xFFFF);
    for (int d = 0; d < stride; d += kLanes) {
        const cv::v_uint16 current = cv::vx_load(previous + d);
        const cv::v_uint16 lower = cv::vx_load(previous + d - 1);  // L(d-1)
        const cv::v_uint16 upper = cv::vx_load(previous + d + 1);  // L(d+1)
        cv::v_uint16 m = cv::v_min(current, cv::v_min(lower, upper) + vP1);  // = min(lower + P1, upper + P1)
        m = cv::v_min(m, vJump);
        const cv::v_uint16 l = cv::vx_load(cost + d) + (m - vMin);
        cv::v_store(out + d, l);
        cv::v_uint16 total = kFirst ? l : cv::vx_load(sum + d) + l;
        if (kExtra) total = total + cv::vx_load(extra + d);
        cv::v_store(sum + d, total);
        newMin = cv::v_min(newMin, l);
    }
    return cv::v_reduce_min(newMin);
}

// The three directions of a vertical pass at one pixel in one go: the same step as above for each
// (previous[i] may be null, unless kAllPrevious: that direction starts its line here, L = C),
// with the sum read and written once instead of three times; the sum starts here (the vertical
// passes run first). minima[i] is min_t L(p - r_i, t) on entry and the new minimum on return.
// kAllPrevious (every pixel but the first row and the two end columns) leaves the null tests out
// of the loop.
template <bool kAllPrevious>
void stepThreeAndStartSum(const std::uint16_t* cost, const std::uint16_t* const previous[3],
                            std::uint16_t minima[3], int stride, const std::uint16_t p1[3],
                            const std::uint16_t p2[3], std::uint16_t* const out[3], std::uint16_t* sum) {
    cv::v_uint16 vMin[3], vJump[3], vP1[3], newMin[3];
    for (int i = 0; i < 3; ++i) {
        vMin[i] = cv::vx_setall_u16(kAllPrevious || previous[i] ? minima[i] : 0);
        vJump[i] = vMin[i] + cv::vx_setall_u16(p2[i]);  // saturating
        vP1[i] = cv::vx_setall_u16(p1[i]);
        newMin[i] = cv::vx_setall_u16(0xFFFF);
    }
    for (int d = 0; d < stride; d += kLanes) {
        const cv::v_uint16 c = cv::vx_load(cost + d);
        cv::v_uint16 total = cv::vx_setzero_u16();
        for (int i = 0; i < 3; ++i) {
            cv::v_uint16 l = c;
            if (kAllPrevious || previous[i]) {
                const std::uint16_t* prev = previous[i];
                // min(L(d-1) + P1, L(d+1) + P1) as min(L(d-1), L(d+1)) + P1: the same, one add fewer.
                cv::v_uint16 m = cv::v_min(cv::vx_load(prev + d),
                                           cv::v_min(cv::vx_load(prev + d - 1), cv::vx_load(prev + d + 1)) + vP1[i]);
                m = cv::v_min(m, vJump[i]);
                l = c + (m - vMin[i]);
            }
            cv::v_store(out[i] + d, l);
            total = total + l;
            newMin[i] = cv::v_min(newMin[i], l);
        }
        cv::v_store(sum + d, total);
    }
    for (int i = 0; i < 3; ++i) minima[i] = cv::v_reduce_min(newMin[i]);
}

// L vectors of `count` pixels, each with a guard of at least one vector of 0xFFFF before it; the
// guard of the next pixel (or the final one) follows it. Each at(i) starts a 64-byte cache line, so
// a pixel's vectors take as few lines as they can (Cones: about 0.5 ms a pair against 16-byte
// alignment).
class LineBuffers {
public:
    static constexpr std::size_t kAlign = kCacheLine / sizeof(std::uint16_t);  // elements
    void create(int count, int stride) {
        pitch_ = (static_cast<std::size_t>(stride) + kLanes + kAlign - 1) / kAlign * kAlign;
        // A whole line of guard before the first pixel; the data starts a line (AlignedVector).
        data_.assign(kAlign + static_cast<std::size_t>(count) * pitch_, std::uint16_t{0xFFFF});
    }
    std::uint16_t* at(int i) { return data_.data() + kAlign + static_cast<std::size_t>(i) * pitch_; }
    std::size_t pitch() const { return pitch_; }

private:
    std::size_t pitch_ = 0;
    AlignedVector<std::uint16_t> data_;
};

// The first pixel of a line: L = C.
template <bool kFirst, bool kExtra = false>
std::uint16_t startLine(const std::uint16_t* cost, int stride, std::uint16_t* out, std::uint16_t* sum,
                        const std::uint16_t* extra = nullptr) {
    cv::v_uint16 newMin = cv::vx_setall_u16(0xFFFF);
    for (int d = 0; d < stride; d += kLanes) {
        const cv::v_uint16 l = cv::vx_load(cost + d);
        cv::v_store(out + d, l);
        cv::v_uint16 total = kFirst ? l : cv::vx_load(sum + d) + l;
        if (kExtra) total = total + cv::vx_load(extra + d);
        cv::v_store(sum + d, total);
        newMin = cv::v_min(newMin, l);
    }
    return cv::v_reduce_min(newMin);
}

// The winner-take-all of a pixel whose sum is complete, read back while it is still in the nearest
// cache (a separate pass would read the whole volume from memory again): the least of the first
// `valid` disparities, ties to the smaller, as winnerTakesAll.
std::int16_t leastDisparity(const std::uint16_t* sum, int valid) {
    const int vectorEnd = valid / kLanes * kLanes;
    std::uint16_t least = 0xFFFF;
    if (vectorEnd > 0) {
        cv::v_uint16 m = cv::vx_load(sum);
        for (int d = kLanes; d < vectorEnd; d += kLanes) m = cv::v_min(m, cv::vx_load(sum + d));
        least = cv::v_reduce_min(m);
    }
    for (int d = vectorEnd; d < valid; ++d) least = std::min(least, sum[d]);
    const cv::v_uint16 target = cv::vx_setall_u16(least);
    for (int d = 0; d < vectorEnd; d += kLanes) {
        const cv::v_uint16 equal = cv::vx_load(sum + d) == target;
        if (cv::v_check_any(equal)) return static_cast<std::int16_t>(d + cv::v_scan_forward(equal));
    }
    int d = vectorEnd;
    while (sum[d] != least) ++d;
    return static_cast<std::int16_t>(d);
}

// The penalty case of every pixel for every direction, computed once per image rather than per
// step (two colour distances per pixel and direction would otherwise sit inside the recurrence).
// For an axis a, below_a(u) = [D_c(u, u - a) < τ]. Direction r = a reads D1 = below_a(p) and
// D2 = below_a(p - a); r = -a reads D1 = below_a(p + a) and D2 = below_a(p + 2a). A neighbour
// outside the image gives D2 = 0, as in the reference: below_a is (0 < τ) where
// u - a is outside and on a border of two pixels around the image.
class PenaltyCases {
public:
    void compute(const cv::Mat& bgr, int tau) {
        const int width = bgr.cols, height = bgr.rows;
        cv::split(bgr, planes_);
        const std::uint8_t outside = 0 < tau ? 1 : 0;
        for (int a = 0; a < 4; ++a) {
            below_[a].create(height + 2 * kBorder, width + 2 * kBorder, CV_8UC1);
            below_[a].setTo(outside);
        }
        for (int i = 0; i < 8; ++i) cases_[i].create(height, width, CV_8UC1);
        forEachStripe(height, [&](int, int begin, int end) {
            for (int a = 0; a < 4; ++a) belowRows(a, begin, end, tau);
        });
        forEachStripe(height, [&](int, int begin, int end) {
            for (int i = 0; i < 8; ++i) caseRows(i, begin, end);
        });
    }
    // Index of r in kDirections.
    const std::uint8_t* row(int direction, int y) const { return cases_[direction].ptr<std::uint8_t>(y); }

private:
    static constexpr int kBorder = 2;
    static constexpr Direction kAxes[4] = {{1, 0}, {0, 1}, {1, 1}, {-1, 1}};

    std::uint8_t* belowAt(int a, int x, int y) { return below_[a].ptr<std::uint8_t>(y + kBorder) + x + kBorder; }

    void belowRows(int a, int begin, int end, int tau) {
        const Direction axis = kAxes[a];
        const int width = planes_[0].cols;
        const cv::v_uint8x16 vTau = cv::v_setall_u8(static_cast<std::uint8_t>(std::clamp(tau, 0, 255)));
        const cv::v_uint8x16 one = cv::v_setall_u8(1);
        for (int y = std::max(begin, axis.dy); y < end; ++y) {
            const int x0 = std::max(0, axis.dx), x1 = std::min(width, width + axis.dx);
            const std::uint8_t* here[3];
            const std::uint8_t* back[3];
            for (int c = 0; c < 3; ++c) {
                here[c] = planes_[c].ptr<std::uint8_t>(y);
                back[c] = planes_[c].ptr<std::uint8_t>(y - axis.dy) - axis.dx;
            }
            std::uint8_t* out = belowAt(a, 0, y);
            int x = x0;
            if (tau <= 255) {
                for (; x + kLanes8 <= x1; x += kLanes8) {
                    cv::v_uint8x16 d = cv::v_absdiff(cv::v_load(here[0] + x), cv::v_load(back[0] + x));
                    d = cv::v_max(d, cv::v_absdiff(cv::v_load(here[1] + x), cv::v_load(back[1] + x)));
                    d = cv::v_max(d, cv::v_absdiff(cv::v_load(here[2] + x), cv::v_load(back[2] + x)));
                    cv::v_store(out + x, (d < vTau) & one);
                }
            }
            for (; x < x1; ++x) {
                const int d = std::max({std::abs(here[0][x] - back[0][x]), std::abs(here[1][x] - back[1][x]),
                                        std::abs(here[2][x] - back[2][x])});
                out[x] = d < tau ? 1 : 0;
            }
        }
    }

    void caseRows(int direction, int begin, int end) {
        const Direction r = kDirections[direction];
        int a = 0;
        while (!((kAxes[a].dx == r.dx && kAxes[a].dy == r.dy) || (kAxes[a].dx == -r.dx && kAxes[a].dy == -r.dy))) ++a;
        const bool forward = kAxes[a].dx == r.dx && kAxes[a].dy == r.dy;
        // The two below_a samples, as offsets from p: (0, -r) forwards, (-r, -2r) backwards.
        const int k1 = forward ? 0 : 1, k2 = forward ? 1 : 2;
        const int width = planes_[0].cols;
        const cv::v_uint8x16 two = cv::v_setall_u8(2);
        for (int y = begin; y < end; ++y) {
            const std::uint8_t* b1 = belowAt(a, -k1 * r.dx, y - k1 * r.dy);
            const std::uint8_t* b2 = belowAt(a, -k2 * r.dx, y - k2 * r.dy);
            std::uint8_t* out = cases_[direction].ptr<std::uint8_t>(y);
            int x = 0;
            for (; x + kLanes8 <= width; x += kLanes8) {
                cv::v_store(out + x, two - cv::v_load(b1 + x) - cv::v_load(b2 + x));
            }
            for (; x < width; ++x) out[x] = static_cast<std::uint8_t>(2 - b1[x] - b2[x]);
        }
    }

    cv::Mat planes_[3];
    cv::Mat below_[4];
    cv::Mat cases_[8];
};

// Left-to-right and right-to-left along every row: rows are independent, split over stripes.
// kFirst: this pass starts the sum. Otherwise the sum holds the down pass's directions and extra
// the up pass's, which are added on the way back, so no separate pass adds them; the sum of each
// pixel is then complete, and `disparity`, when given, takes its winner.
template <bool kFirst>
void horizontalPass(const CostVolume& costs, const PenaltyCases& cases, const ScanlinePenalties& penalties,
                    CostVolume& sum, const CostVolume* extra = nullptr, cv::Mat* disparity = nullptr) {
    CV_Assert(kFirst || extra);
    CV_Assert(!(kFirst && disparity));
    const int width = costs.width, stride = costs.stride, disparities = costs.disparities;
    forEachStripe(costs.height, [&](int, int begin, int end) {
        LineBuffers buffers;
        buffers.create(2, stride);
        std::uint16_t* previous = buffers.at(0);
        std::uint16_t* current = buffers.at(1);
        for (int y = begin; y < end; ++y) {
            const std::uint8_t* rightwards = cases.row(0, y);
            const std::uint8_t* leftwards = cases.row(1, y);
            std::uint16_t minimum = startLine<kFirst>(costs.at(0, y), stride, previous, sum.at(0, y));
            for (int x = 1; x < width; ++x) {
                const int c = rightwards[x];
                minimum = stepAndAccumulate<kFirst>(costs.at(x, y), previous, minimum, stride, penalties.p1[c],
                                                    penalties.p2[c], current, sum.at(x, y));
                std::swap(previous, current);
            }
            // On the way back the other vertical pass's directions come in too (kFirst false).
            auto spareAt = [&](int x) { return kFirst ? nullptr : extra->at(x, y); };
            std::int16_t* winners = disparity ? disparity->ptr<std::int16_t>(y) : nullptr;
            minimum = startLine<false, !kFirst>(costs.at(width - 1, y), stride, previous, sum.at(width - 1, y),
                                                spareAt(width - 1));
            if (winners) winners[width - 1] = leastDisparity(sum.at(width - 1, y), std::min(disparities, width));
            for (int x = width - 2; x >= 0; --x) {
                const int c = leftwards[x];
                minimum = stepAndAccumulate<false, !kFirst>(costs.at(x, y), previous, minimum, stride, penalties.p1[c],
                                                            penalties.p2[c], current, sum.at(x, y), spareAt(x));
                std::swap(previous, current);
                // Left pixel x has candidates d <= x only.
                if (winners) winners[x] = leastDisparity(sum.at(x, y), std::min(disparities, x + 1));
            }
        }
    });
}

// The three directions that go down (dy = 1) or up (dy = -1), row after row: each row depends
// only on the previous one. The whole pass runs on one thread: splitting each row's columns over
// threads needs a wait for every row, and those waits cost more than the second core gave (the
// down and the up pass run side by side instead, see aggregateScanlines). One read of the costs
// and one write of the sum serve all three directions; the sum starts here.
// Each direction keeps one row of L instead of two (a 1280-pixel row at 128 disparities: 1.2 MiB
// instead of 2.4, within a core's own cache), the new row replacing the old as x advances, through
// a table of cell pointers so that nothing is copied. (-1, dy) reads cell x + 1, not yet replaced,
// and writes cell x in place. (0, dy) reads cell x and writes a spare cell, which then takes cell
// x's place. (1, dy) reads cell x - 1, which must still hold the old row when pixel x reads it:
// pixel x - 1's new L waits in one of two spare cells and takes its place after pixel x.
void verticalPass(const CostVolume& costs, const PenaltyCases& cases, const ScanlinePenalties& penalties, int dy,
                  CostVolume& sum) {
    const int width = costs.width, height = costs.height, stride = costs.stride;
    const Direction directions[3] = {{0, dy}, {1, dy}, {-1, dy}};
    const int caseIndex[3] = {dy > 0 ? 2 : 3, dy > 0 ? 4 : 6, dy > 0 ? 7 : 5};  // in kDirections
    LineBuffers storage;  // width cells per direction and three spares
    storage.create(3 * width + 3, stride);
    std::vector<std::uint16_t*> cells(3 * static_cast<std::size_t>(width));
    for (std::size_t k = 0; k < cells.size(); ++k) cells[k] = storage.at(static_cast<int>(k));
    std::uint16_t* spare0 = storage.at(3 * width);
    std::uint16_t* held[2] = {storage.at(3 * width + 1), storage.at(3 * width + 2)};
    auto cell = [&](int i, int x) -> std::uint16_t*& { return cells[static_cast<std::size_t>(i) * width + x]; };
    std::vector<std::uint16_t> minima(3 * static_cast<std::size_t>(width));
    std::uint16_t* lineMin[3];
    for (int i = 0; i < 3; ++i) lineMin[i] = minima.data() + i * static_cast<std::size_t>(width);
    std::uint16_t heldMin[2] = {0, 0};
    // Pixel x's held-back L of (1, dy) into the row.
    auto commit = [&](int x) {
        std::swap(cell(1, x), held[x & 1]);
        lineMin[1][x] = heldMin[x & 1];
    };
    for (int step = 0; step < height; ++step) {
        const int y = dy > 0 ? step : height - 1 - step;
        const std::uint8_t* caseRow[3];
        for (int i = 0; i < 3; ++i) caseRow[i] = cases.row(caseIndex[i], y);
        auto pixel = [&](auto allPrevious, int x) {
            const std::uint16_t* from[3];
            std::uint16_t* const out[3] = {spare0, held[x & 1], cell(2, x)};
            std::uint16_t minimum[3], p1[3], p2[3];
            for (int i = 0; i < 3; ++i) {
                const int px = x - directions[i].dx;
                const bool starts = !allPrevious && (step == 0 || px < 0 || px >= width);
                from[i] = starts ? nullptr : cell(i, px);
                minimum[i] = starts ? 0 : lineMin[i][px];
                const int c = caseRow[i][x];
                p1[i] = penalties.p1[c];
                p2[i] = penalties.p2[c];
            }
            stepThreeAndStartSum<decltype(allPrevious)::value>(costs.at(x, y), from, minimum, stride, p1, p2, out,
                                                               sum.at(x, y));
            std::swap(cell(0, x), spare0);
            lineMin[0][x] = minimum[0];
            heldMin[x & 1] = minimum[1];
            lineMin[2][x] = minimum[2];
            if (x > 0) commit(x - 1);
        };
        if (step == 0 || width < 3) {
            for (int x = 0; x < width; ++x) pixel(std::false_type{}, x);
        } else {
            pixel(std::false_type{}, 0);
            for (int x = 1; x < width - 1; ++x) pixel(std::true_type{}, x);
            pixel(std::false_type{}, width - 1);
        }
        commit(width - 1);
    }
}

// Straight down and straight up alone (the 4-direction sum): columns are independent, so they are
// split over stripes once, with no wait between rows. A block of neighbouring columns runs down,
// then up, together: walking one column alone would jump a whole image row in memory for every
// pixel's few cache lines, and the hardware prefetcher does not follow that. The up pass completes
// each pixel's sum; `disparity`, when given, takes its winner.
// The block's cells a few rows ahead are asked for before they are needed (prefetchCells).
constexpr int kColumnBlock = 8;
void columnPass(const CostVolume& costs, const PenaltyCases& cases, const ScanlinePenalties& penalties,
                CostVolume& sum, cv::Mat* disparity) {
    const int height = costs.height, stride = costs.stride, disparities = costs.disparities;
    forEachStripe(costs.width, [&](int, int begin, int end) {
        LineBuffers buffers;
        buffers.create(2 * kColumnBlock, stride);
        std::uint16_t minimum[kColumnBlock];
        for (int x0 = begin; x0 < end; x0 += kColumnBlock) {
            const int columns = std::min(kColumnBlock, end - x0);
            for (const int dy : {1, -1}) {
                const int caseIndex = dy > 0 ? 2 : 3;  // in kDirections
                std::uint16_t* previous[kColumnBlock];
                std::uint16_t* current[kColumnBlock];
                const int y0 = dy > 0 ? 0 : height - 1;
                const bool last = dy < 0 && disparity;
                auto takeWinners = [&](int y) {
                    std::int16_t* winners = disparity->ptr<std::int16_t>(y);
                    for (int k = 0; k < columns; ++k) {
                        // Left pixel x has candidates d <= x only.
                        winners[x0 + k] = leastDisparity(sum.at(x0 + k, y), std::min(disparities, x0 + k + 1));
                    }
                };
                for (int k = 0; k < columns; ++k) {
                    previous[k] = buffers.at(2 * k);
                    current[k] = buffers.at(2 * k + 1);
                    minimum[k] = startLine<false>(costs.at(x0 + k, y0), stride, previous[k], sum.at(x0 + k, y0));
                }
                if (last) takeWinners(y0);
                for (int step = 1; step < height; ++step) {
                    const int y = y0 + dy * step;
                    const std::uint8_t* c = cases.row(caseIndex, y) + x0;
                    if (step + kPrefetchRows < height) {
                        prefetchCells(costs.at(x0, y + kPrefetchRows * dy), columns * stride, false);
                        prefetchCells(sum.at(x0, y + kPrefetchRows * dy), columns * stride, true);
                    }
                    for (int k = 0; k < columns; ++k) {
                        minimum[k] = stepAndAccumulate<false>(costs.at(x0 + k, y), previous[k], minimum[k], stride,
                                                              penalties.p1[c[k]], penalties.p2[c[k]], current[k],
                                                              sum.at(x0 + k, y));
                        std::swap(previous[k], current[k]);
                    }
                    if (last) takeWinners(y);
                }
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
                        CostVolume& sum, int directions, CostVolume* spare, cv::Mat* disparity) {
    CV_Assert(directions == 8 || directions == 4);
    CV_Assert(bgr.type() == CV_8UC3 && bgr.cols == costs.width && bgr.rows == costs.height);
    sum.create(costs.width, costs.height, costs.disparities);
    if (disparity) disparity->create(costs.height, costs.width, CV_16SC1);
    thread_local PenaltyCases cases;  // reallocated only when the image size changes
    cases.compute(bgr, penalties.tau);
    if (directions == 4) {
        // Two sweeps over the volume instead of four.
        horizontalPass<true>(costs, cases, penalties, sum);
        columnPass(costs, cases, penalties, sum, disparity);
        return;
    }
    // Three sweeps over the volume instead of eight. The down pass starts the sum while the up
    // pass, on the other thread, fills the spare volume; the horizontal pass then adds both
    // directions of its own and the spare. The same sums whatever the thread count: no sum comes
    // near saturation (Parameters caps the penalties), so the order of the additions is free.
    thread_local CostVolume ownSpare;
    CostVolume& up = spare ? *spare : ownSpare;
    up.create(costs.width, costs.height, costs.disparities);
    const PenaltyCases& sharedCases = cases;  // the tasks run on other threads: not their thread_local
    cv::parallel_for_(cv::Range(0, 2), [&](const cv::Range& r) {
        for (int task = r.start; task < r.end; ++task) {
            verticalPass(costs, sharedCases, penalties, task == 0 ? 1 : -1, task == 0 ? sum : up);
        }
    }, 2);
    horizontalPass<false>(costs, cases, penalties, sum, &up, disparity);
}

void aggregateScanlinesReference(const CostVolume& costs, const cv::Mat& bgr, const ScanlinePenalties& penalties,
                                 CostVolume& sum, int directions) {
    sum.create(costs.width, costs.height, costs.disparities);
    std::fill(sum.data.begin(), sum.data.end(), 0);
    const int stride = costs.stride;
    CostVolume l;
    l.create(costs.width, costs.height, costs.disparities);
    for (const Direction r : kDirections) {
        if (directions == 4 && r.dx != 0 && r.dy != 0) continue;
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
