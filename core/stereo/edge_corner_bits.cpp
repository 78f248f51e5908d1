// The edge and corner flags of the improved Census' four-bit code: Canny edges (L2 gradient norm)
// and Harris corners, both from one pair of 3x3 Sobel derivatives.
//
// Both give exactly what OpenCV's cv::Canny and a cv::boxFilter-based Harris give (the tests
// compare them), but OpenCV's general routines took most of the Census inputs' time: Canny keeps
// per-stripe deques of pixel pointers, and the Harris products went through a three-channel float
// box filter in fresh buffers. Here the non-maximum suppression runs a vector of pixels at a time
// without branches, hysteresis follows a plain index stack, and the Harris sums are exact integer
// sums (the products and their 3x3 sums are integers below 2^24, which the float filter also held
// exactly), made row by row in a ring of three product rows.
#include <algorithm>
#include <cmath>

#include "core/common/simd.hpp"

#include "core/stereo/stages.hpp"

namespace icewatch::stereo::detail {

namespace {

// tan(22.5°) in Q15, as OpenCV rounds it: |dy| < tan(22.5°) |dx| is a horizontal gradient,
// |dy| > tan(67.5°) |dx| = (tan(22.5°) + 2) |dx| a vertical one, anything between a diagonal.
constexpr int kTan22 = 13573;
constexpr int kShift = 15;

// Non-maximum suppression map values, as OpenCV's: 0 a weak edge (above the low threshold and a
// local maximum), 1 no edge, 2 a strong edge (above the high threshold too).
constexpr std::uint8_t kWeak = 0, kNone = 1, kStrong = 2;

// One pixel of the suppression: m its squared gradient, `mag` its place in the magnitude rows
// (rows `step` apart, zero outside the image).
std::uint8_t suppressOne(const std::int32_t* mag, std::ptrdiff_t step, int dx, int dy, int low, int high) {
    const int m = mag[0];
    if (m <= low) return kNone;
    const int ax = std::abs(dx), ay = std::abs(dy) << kShift;
    const int tg22x = ax * kTan22;
    bool maximum;
    if (ay < tg22x) {
        maximum = m > mag[-1] && m >= mag[1];
    } else if (ay > tg22x + (ax << (kShift + 1))) {
        maximum = m > mag[-step] && m >= mag[step];
    } else {
        const int s = (dx ^ dy) < 0 ? -1 : 1;
        maximum = m > mag[-step - s] && m > mag[step + s];
    }
    if (!maximum) return kNone;
    return m > high ? kStrong : kWeak;
}

// The same for a vector of 32-bit lanes.
cv::v_int32 suppressLanes(const std::int32_t* mag, std::ptrdiff_t step, const cv::v_int32& dx, const cv::v_int32& dy,
                          const cv::v_int32& low, const cv::v_int32& high) {
    const cv::v_int32 m = cv::vx_load(mag);
    const cv::v_int32 ax = cv::v_reinterpret_as_s32(cv::v_abs(dx));
    const cv::v_int32 ay = cv::v_reinterpret_as_s32(cv::v_abs(dy)) << kShift;
    const cv::v_int32 tg22x = ax * cv::vx_setall_s32(kTan22);
    const cv::v_int32 horizontal = ay < tg22x;
    const cv::v_int32 vertical = ay > tg22x + (ax << (kShift + 1));
    const cv::v_int32 alongRow = (m > cv::vx_load(mag - 1)) & (m >= cv::vx_load(mag + 1));
    const cv::v_int32 alongColumn = (m > cv::vx_load(mag - step)) & (m >= cv::vx_load(mag + step));
    // Same signs (s = 1): the diagonal from the upper left; else from the upper right.
    const cv::v_int32 sameSign = (dx ^ dy) >= cv::vx_setzero_s32();
    const cv::v_int32 mainDiagonal = (m > cv::vx_load(mag - step - 1)) & (m > cv::vx_load(mag + step + 1));
    const cv::v_int32 antiDiagonal = (m > cv::vx_load(mag - step + 1)) & (m > cv::vx_load(mag + step - 1));
    const cv::v_int32 diagonal = cv::v_select(sameSign, mainDiagonal, antiDiagonal);
    const cv::v_int32 maximum =
        (m > low) & cv::v_select(horizontal, alongRow, cv::v_select(vertical, alongColumn, diagonal));
    const cv::v_int32 none = cv::vx_setall_s32(kNone), strong = cv::vx_setall_s32(kStrong);
    return cv::v_select(maximum, cv::v_select(m > high, strong, cv::vx_setzero_s32()), none);
}

// Canny's map, kStrong on edges, with a border of one pixel (in the scratch's cannyCells).
struct CannyMap {
    const std::vector<std::uint8_t>& cells;
    std::size_t step;  // width + 2
    const std::uint8_t* row(int y) const { return cells.data() + (static_cast<std::size_t>(y) + 1) * step + 1; }
};

CannyMap cannyMap(const cv::Mat& dx, const cv::Mat& dy, double lowThreshold, double highThreshold,
                  EyeScratch& scratch) {
    const int width = dx.cols, height = dx.rows;
    // Thresholds on the squared norm, as cv::Canny turns them.
    if (lowThreshold > highThreshold) std::swap(lowThreshold, highThreshold);
    lowThreshold = std::min(32767.0, lowThreshold);
    highThreshold = std::min(32767.0, highThreshold);
    if (lowThreshold > 0) lowThreshold *= lowThreshold;
    if (highThreshold > 0) highThreshold *= highThreshold;
    const int low = cvFloor(lowThreshold), high = cvFloor(highThreshold);

    // Squared gradients with a border of zeros, and the map with a border of kNone; only the
    // borders need setting, the rest is written below.
    const std::ptrdiff_t step = width + 2;
    std::vector<std::int32_t>& magnitude = scratch.magnitude;
    std::vector<std::uint8_t>& map = scratch.cannyCells;
    std::vector<std::int32_t>& stack = scratch.stack;
    stack.clear();
    magnitude.resize(static_cast<std::size_t>(step * (height + 2)));
    std::fill(magnitude.begin(), magnitude.begin() + step, 0);
    std::fill(magnitude.end() - step, magnitude.end(), 0);
    map.resize(static_cast<std::size_t>(step * (height + 2)));
    std::fill(map.begin(), map.begin() + step, kNone);
    std::fill(map.end() - step, map.end(), kNone);
    auto magAt = [&](int y) { return magnitude.data() + (y + 1) * step + 1; };
    auto mapAt = [&](int y) { return map.data() + (y + 1) * step + 1; };

    constexpr int kLanes16 = cv::v_int16::nlanes, kLanes32 = cv::v_int32::nlanes;
    for (int y = 0; y < height; ++y) {
        const auto* gx = dx.ptr<std::int16_t>(y);
        const auto* gy = dy.ptr<std::int16_t>(y);
        std::int32_t* m = magAt(y);
        m[-1] = m[width] = 0;
        int x = 0;
        for (; x + kLanes16 <= width; x += kLanes16) {
            cv::v_int32 x0, x1, y0, y1;
            cv::v_expand(cv::vx_load(gx + x), x0, x1);
            cv::v_expand(cv::vx_load(gy + x), y0, y1);
            cv::v_store(m + x, x0 * x0 + y0 * y0);
            cv::v_store(m + x + kLanes32, x1 * x1 + y1 * y1);
        }
        for (; x < width; ++x) m[x] = gx[x] * gx[x] + gy[x] * gy[x];
    }

    const cv::v_int32 vLow = cv::vx_setall_s32(low), vHigh = cv::vx_setall_s32(high);
    for (int y = 0; y < height; ++y) {
        const auto* gx = dx.ptr<std::int16_t>(y);
        const auto* gy = dy.ptr<std::int16_t>(y);
        const std::int32_t* m = magAt(y);
        std::uint8_t* out = mapAt(y);
        out[-1] = out[width] = kNone;
        int x = 0;
        for (; x + kLanes16 <= width; x += kLanes16) {
            cv::v_int32 x0, x1, y0, y1;
            cv::v_expand(cv::vx_load(gx + x), x0, x1);
            cv::v_expand(cv::vx_load(gy + x), y0, y1);
            const cv::v_int32 a = suppressLanes(m + x, step, x0, y0, vLow, vHigh);
            const cv::v_int32 b = suppressLanes(m + x + kLanes32, step, x1, y1, vLow, vHigh);
            cv::v_pack_u_store(out + x, cv::v_pack(a, b));
        }
        for (; x < width; ++x) out[x] = suppressOne(m + x, step, gx[x], gy[x], low, high);
    }

    // Hysteresis: weak edges 8-connected to a strong one become strong. (OpenCV visits them in
    // another order; the connected set is the same.)
    stack.clear();
    for (int y = 0; y < height; ++y) {
        const std::uint8_t* row = mapAt(y);
        const auto offset = static_cast<std::int32_t>((y + 1) * step + 1);
        for (int x = 0; x < width; ++x)
            if (row[x] == kStrong) stack.push_back(offset + x);
    }
    const auto s = static_cast<std::int32_t>(step);
    const std::int32_t neighbours[8] = {-s - 1, -s, -s + 1, -1, 1, s - 1, s, s + 1};
    std::uint8_t* const cells = map.data();
    while (!stack.empty()) {
        const std::int32_t at = stack.back();
        stack.pop_back();
        for (const std::int32_t n : neighbours) {
            if (cells[at + n] == kWeak) {
                cells[at + n] = kStrong;
                stack.push_back(at + n);
            }
        }
    }
    return {map, static_cast<std::size_t>(step)};
}

}  // namespace

void cannyEdges(const cv::Mat& dx, const cv::Mat& dy, double low, double high, cv::Mat& edges) {
    CV_Assert(dx.type() == CV_16SC1 && dy.type() == CV_16SC1 && dx.size() == dy.size());
    edges.create(dx.size(), CV_8UC1);
    if (dx.empty()) return;
    EyeScratch scratch;
    const CannyMap map = cannyMap(dx, dy, low, high, scratch);
    for (int y = 0; y < dx.rows; ++y) {
        const std::uint8_t* row = map.row(y);
        auto* out = edges.ptr<std::uint8_t>(y);
        for (int x = 0; x < dx.cols; ++x) out[x] = row[x] == kStrong ? 255 : 0;
    }
}

cv::Mat edgeCornerBits(const cv::Mat& grey, const Parameters& parameters, EyeScratch* scratch) {
    CV_Assert(grey.type() == CV_8UC1);
    cv::Mat bits(grey.size(), CV_8UC1);
    if (grey.empty()) return bits;
    // One pair of derivatives serves both detectors: Canny's own (3x3 Sobel, replicated border)
    // and Harris' (the same Sobel; its scale does not matter, the threshold is relative to the
    // largest response).
    EyeScratch own;
    EyeScratch& s = scratch ? *scratch : own;
    const cv::Mat& dx = s.dx;
    const cv::Mat& dy = s.dy;
    sobel16(grey, s.dx, s.dy);
    const CannyMap map = cannyMap(dx, dy, parameters.cannyLowThreshold, parameters.cannyHighThreshold, s);

    // Harris, k = 0.04 over 3x3 blocks (replicated border) of the products of the derivatives:
    // exact integer sums, per row a vertical sum of three product rows, then a horizontal one.
    // Product rows are made as the sums need them, in a ring of three.
    const int width = grey.cols, height = grey.rows;
    const auto columns = static_cast<std::size_t>(width);
    thread_local std::vector<std::int32_t> ring;       // 3 rows x (gx², gx gy, gy²)
    thread_local std::vector<std::int32_t> sums;       // one row's vertical sums, a replicated column each side
    std::vector<double>& response = s.response;
    ring.resize(9 * columns);
    sums.resize(3 * (columns + 2));
    response.resize(columns * static_cast<std::size_t>(height));
    auto productRow = [&](int y, int k) { return ring.data() + (static_cast<std::size_t>(y % 3) * 3 + k) * columns; };
    constexpr int kLanes16 = cv::v_int16::nlanes, kLanes32 = cv::v_int32::nlanes;
    auto makeProducts = [&](int y) {
        const auto* gx = dx.ptr<std::int16_t>(y);
        const auto* gy = dy.ptr<std::int16_t>(y);
        std::int32_t* xx = productRow(y, 0);
        std::int32_t* xy = productRow(y, 1);
        std::int32_t* yy = productRow(y, 2);
        int x = 0;
        for (; x + kLanes16 <= width; x += kLanes16) {
            cv::v_int32 x0, x1, y0, y1;
            cv::v_expand(cv::vx_load(gx + x), x0, x1);
            cv::v_expand(cv::vx_load(gy + x), y0, y1);
            cv::v_store(xx + x, x0 * x0);
            cv::v_store(xx + x + kLanes32, x1 * x1);
            cv::v_store(xy + x, x0 * y0);
            cv::v_store(xy + x + kLanes32, x1 * y1);
            cv::v_store(yy + x, y0 * y0);
            cv::v_store(yy + x + kLanes32, y1 * y1);
        }
        for (; x < width; ++x) {
            xx[x] = gx[x] * gx[x];
            xy[x] = gx[x] * gy[x];
            yy[x] = gy[x] * gy[x];
        }
    };
    makeProducts(0);
    double maxResponse = 0.0;
    for (int y = 0; y < height; ++y) {
        if (y + 1 < height) makeProducts(y + 1);  // in the place of row y - 2, which no sum needs any more
        const int above = std::max(y - 1, 0), below = std::min(y + 1, height - 1);
        for (int k = 0; k < 3; ++k) {
            const std::int32_t* a = productRow(above, k);
            const std::int32_t* b = productRow(y, k);
            const std::int32_t* c = productRow(below, k);
            std::int32_t* sum = sums.data() + k * (columns + 2) + 1;
            int x = 0;
            for (; x + kLanes32 <= width; x += kLanes32) {
                cv::v_store(sum + x, cv::vx_load(a + x) + cv::vx_load(b + x) + cv::vx_load(c + x));
            }
            for (; x < width; ++x) sum[x] = a[x] + b[x] + c[x];
            sum[-1] = sum[0];
            sum[width] = sum[width - 1];
        }
        const std::int32_t* sxx = sums.data() + 1;
        const std::int32_t* sxy = sxx + columns + 2;
        const std::int32_t* syy = sxy + columns + 2;
        double* out = response.data() + static_cast<std::size_t>(y) * columns;
        for (int x = 0; x < width; ++x) {
            const double a = sxx[x - 1] + sxx[x] + sxx[x + 1];
            const double b = sxy[x - 1] + sxy[x] + sxy[x + 1];
            const double c = syy[x - 1] + syy[x] + syy[x + 1];
            out[x] = a * c - b * b - 0.04 * (a + c) * (a + c);
            maxResponse = std::max(maxResponse, out[x]);
        }
    }
    const double cornerLimit = parameters.harrisThreshold * maxResponse;
    for (int y = 0; y < height; ++y) {
        const std::uint8_t* e = map.row(y);
        const double* r = response.data() + static_cast<std::size_t>(y) * columns;
        auto* out = bits.ptr<std::uint8_t>(y);
        for (int x = 0; x < width; ++x) {
            const bool corner = maxResponse > 0.0 && r[x] > cornerLimit;
            out[x] = static_cast<std::uint8_t>((e[x] == kStrong ? 2 : 0) + (corner ? 1 : 0));
        }
    }
    return bits;
}

}  // namespace icewatch::stereo::detail
