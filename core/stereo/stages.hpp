#pragma once
// The stages of the Census-based matchers (Paper and AdCensus), one .cpp per stage. Internal to
// core/stereo: the public interface is matcher.hpp. Every optimised kernel has a plain
// *Reference twin computing the same integers; tests compare the two exactly.

#include <cstdint>
#include <functional>
#include <vector>

#include <opencv2/core.hpp>

#include "core/common/fixed_bands.hpp"
#include "core/common/huge_pages.hpp"
#include "core/stereo/matcher.hpp"
#include "core/stereo/parameters.hpp"

namespace icewatch::stereo::detail {

// Costs are 16-bit fixed point: 1.0 of a fused cost term is kCostScale. The scanline sum of 8
// directions stays below 65536 as long as cost + P2 <= 8191 (the config limits Pi2 for that).
inline constexpr int kCostScale = 512;
// The disparity axis is padded to a multiple of the widest vector's 16-bit lanes (16 with AVX2,
// 8 with SSE or NEON); padded cells hold kPadCost so they never win a minimum.
inline constexpr int kDisparityAlign = 16;
inline constexpr std::uint16_t kPadCost = 0xFFFF;
// Work is split into this many stripes whatever the core count, so results never depend on it.
inline constexpr int kStripes = kFixedBands;

// Resizes a scratch buffer to exactly n elements: a smaller size gives memory back, and the old
// block is freed before the new one is taken (never both at once). Same size: nothing happens.
template <class T>
void resizeExactly(AlignedVector<T>& buffer, std::size_t n) {
    if (n == buffer.size()) return;
    buffer.clear();
    buffer.shrink_to_fit();
    buffer.resize(n);
}

inline int paddedDisparities(int disparities) {
    return (disparities + kDisparityAlign - 1) / kDisparityAlign * kDisparityAlign;
}

// cost(x, y, d) at data[(y * width + x) * stride + d]; stride = paddedDisparities(disparities).
struct CostVolume {
    int width = 0;
    int height = 0;
    int disparities = 0;
    int stride = 0;
    AlignedVector<std::uint16_t> data;

    // Allocates only when the number of cells changes (one allocation per image size and band
    // width), and then exactly that many: a narrower band or a smaller region gives memory back.
    void create(int w, int h, int d);
    std::uint16_t* at(int x, int y) { return data.data() + (static_cast<std::size_t>(y) * width + x) * stride; }
    const std::uint16_t* at(int x, int y) const {
        return data.data() + (static_cast<std::size_t>(y) * width + x) * stride;
    }
};

// Asks for the cache lines of `count` 16-bit cells from `cells` on, to read (and, forWriting, to
// write). The passes that walk a block of columns down a volume ask for the block's cells
// kPrefetchRows rows ahead: rows lie a whole image row apart, which the hardware prefetchers do not
// follow, and each step would otherwise wait for memory. (Cones: about 1 ms of a pair's 60 in each
// of the two passes that do it.)
inline constexpr int kPrefetchRows = 6;
inline void prefetchCells(const std::uint16_t* cells, int count, bool forWriting) {
    const auto* bytes = reinterpret_cast<const char*>(cells);
    constexpr int kCacheLine = 64;
    for (int b = 0; b < count * 2; b += kCacheLine) {
        if (forWriting) {
            __builtin_prefetch(bytes + b, 1);
        } else {
            __builtin_prefetch(bytes + b, 0);
        }
    }
}

// Per-pixel Census bit strings, `words` 64-bit words per pixel, of `height` image rows from
// firstRow on (a block of rows: CensusEncoder). After viewColumns, at(x, y) reads the stored
// column first + x: the codes of a column band, computed on the whole image.
struct CensusImage {
    int width = 0;
    int height = 0;
    int words = 0;
    int first = 0;        // stored column of the view's column 0
    int storedWidth = 0;  // pixels per stored row
    int firstRow = 0;     // image row of the stored row 0
    AlignedVector<std::uint64_t> data;  // each pixel's words on one cache line

    void create(int w, int h, int wordsPerPixel, int firstStoredRow = 0);
    void viewColumns(int firstColumn, int count) {
        first = firstColumn;
        width = count;
    }
    std::uint64_t* at(int x, int y) { return data.data() + index(x, y); }
    const std::uint64_t* at(int x, int y) const { return data.data() + index(x, y); }

private:
    std::size_t index(int x, int y) const {
        return (static_cast<std::size_t>(y - firstRow) * storedWidth + first + x) * words;
    }
};

// Arm lengths (pixels, not counting p itself) of each pixel's cross.
struct CrossArms {
    cv::Mat left, right, up, down;  // CV_8UC1
    cv::Mat planes[3];              // scratch of computeCrossArms: the colour planes with a border
};

// Runs fn(stripe, begin, end) over kStripes fixed slices of [0, count), in parallel.
template <class F>
void forEachStripe(int count, const F& fn) {
    forEachFixedBand(static_cast<std::size_t>(count), [&](int stripe, std::size_t begin, std::size_t end) {
        fn(stripe, static_cast<int>(begin), static_cast<int>(end));
    });
}

// ---- impulse_filter.cpp -----------------------------------------------------------------------
// Switching median: a pixel whose grey value differs from its 3x3 median by more than threshold
// (an impulse: a dead, hot or bit-flipped pixel) takes the median colour; all others are kept.
// An isolated pixel at 0 or 255 (no 8-neighbour at its value: a dead or saturated sensor pixel)
// needs to differ by more than railThreshold only (0: no such rule).
// bgr CV_8UC3 and its grey version, both filtered in place. Returns the number replaced.
int removeImpulses(cv::Mat& bgr, cv::Mat& grey, int threshold, int railThreshold = 0);

// ---- noise_smoothing.cpp ------------------------------------------------------------------------
// Sensor noise level of a grey image, grey levels (Immerkær's estimator over 8x8 blocks at the
// given percentile; at the 5th: about 3/4 of the noise's standard deviation).
double estimateNoiseSigma(const cv::Mat& grey, double percentile = 5.0);
// Blurs bgr (CV_8UC3) with a Gaussian of sigma = clamp(gain * (noise - 1), 0, 0.8) when that is
// above 0.2 and recomputes grey from it; then, when the flattest 1 % of grey's blocks still read
// more than one grey level of noise, passes grey alone through a bilateral filter whose range
// follows the noise (noise_smoothing.cpp explains). Returns the Gaussian's sigma (0: none).
// greyPassRange is the filter's range in noise estimates (0: no grey pass). Gain 0 leaves both
// images alone. noiseLeft, when given, receives estimateNoiseSigma of grey as it is left, which
// the function mostly has at hand already.
double smoothNoise(cv::Mat& bgr, cv::Mat& grey, double gain, double greyPassRange = 3.0,
                   double* noiseLeft = nullptr);
// The Census band for both eyes: max(alpha, round(gain * mean of the two noise estimates));
// gain 0 returns alpha.
int noiseAdaptiveCensusAlpha(int alpha, double gain, double noiseLeft, double noiseRight);

// ---- census.cpp -------------------------------------------------------------------------------
// Improved Census (Paper): per neighbour a four-bit nibble [brighter, darker, edge, corner], 16
// nibbles per word, neighbours in row-major window order without the centre. Words 0-2 hold the
// 7x7 code (48 neighbours), words 3-7 the 9x9 code (80 neighbours).
inline constexpr int kImprovedCensusWords = 8;
inline constexpr int kCensus7Offset = 0;
inline constexpr int kCensus7Words = 3;
inline constexpr int kCensus9Offset = 3;
inline constexpr int kCensus9Words = 5;

// 3x3 Sobel derivatives of an 8-bit image (any channel count, replicated border), exact in 16
// bits, CV_16S. Sobel / 8 is the slope in grey levels per pixel on a ramp, with the usual 3x3
// smoothing.
void sobel16(const cv::Mat& image, cv::Mat& dx, cv::Mat& dy);
// 1 where the 7x7 window applies (gradient magnitude > threshold), 0 for 9x9. CV_8UC1.
// Image-sized scratch of the per-eye stages below, which the matcher keeps between pairs of one
// size (fresh buffers of this size cost more in page faults than the work done in them) unless
// told not to keep buffers (Matcher::setKeepBuffers). Without one, a stage uses its own for the
// call.
struct EyeScratch {
    cv::Mat dx, dy;                       // 3x3 Sobel of the grey image
    cv::Mat colourDx, colourDy;           // and of the colour one
    std::vector<std::int32_t> magnitude;  // Canny: squared gradients with a border
    std::vector<std::uint8_t> cannyCells; // Canny: the map with a border
    std::vector<std::int32_t> stack;      // Canny: the hysteresis stack
    std::vector<double> response;         // Harris
};
cv::Mat censusWindowMask(const cv::Mat& grey, double gradientThreshold, EyeScratch* scratch = nullptr);
// Per-pixel gradient magnitude of each colour channel, 3x3 Sobel / 8 in grey levels per pixel,
// times kGradientSteps, rounded and saturated, CV_8UC3.
inline constexpr int kGradientSteps = 4;
cv::Mat channelGradientMagnitudes(const cv::Mat& bgr, EyeScratch* scratch = nullptr);
// windowMask: which code each pixel needs (1 = 7x7, 0 = 9x9); empty computes both codes (the
// right image, whose pixels are compared with left pixels of either window).
void improvedCensus(const cv::Mat& grey, const cv::Mat& edgeCorner, int alpha, const cv::Mat& windowMask,
                    CensusImage& out);
void improvedCensusReference(const cv::Mat& grey, const cv::Mat& edgeCorner, int alpha,
                             const cv::Mat& windowMask, CensusImage& out);
// Mei's Census: 9x7 window on grey, 1 bit per neighbour (neighbour < centre), one word.
void meiCensus(const cv::Mat& grey, CensusImage& out);
// The codes of one image a few rows at a time, as improvedCensus or meiCensus computes them for
// the whole image. A row's matching costs need that row's codes only, and the whole image's
// (64 bytes a pixel for the improved code) were the matcher's largest buffers after the cost
// volumes: the cost stage codes each row as it needs it (CostInputs::encoder). prepare* copies
// what every row reads, once.
class CensusEncoder {
public:
    void prepareImproved(const cv::Mat& grey, const cv::Mat& edgeCorner, int alpha, const cv::Mat& windowMask);
    void prepareMei(const cv::Mat& grey);
    int words() const;  // per pixel
    // Rows [begin, end) into out (out.firstRow = begin), every column: split over stripes, or on
    // the calling thread alone.
    void encodeRows(int begin, int end, CensusImage& out) const;
    void encodeRowsHere(int begin, int end, CensusImage& out) const;

private:
    void encodeInto(int begin, int end, CensusImage& out) const;
    void encodeImprovedRows(int begin, int end, CensusImage& out) const;
    void encodeMeiRows(int begin, int end, CensusImage& out) const;

    bool improved_ = true;
    cv::Size size_;
    int alpha_ = 0;
    cv::Mat windowMask_;
    // Padded, all of one step: grey, the same with the sign bit flipped (the improved code's
    // thresholds compare signed bytes), the edge-corner bits, and those in the upper nibble for the
    // odd neighbours.
    cv::Mat padded_, signedGrey_, ec_, ecHigh_;
    std::vector<int> offsets_;  // byte offsets of the 7x7 then the 9x9 window's neighbours
};

// ---- edge_corner_bits.cpp ---------------------------------------------------------------------
// bit 1 = Canny edge, bit 0 = Harris corner (response > harrisThreshold x the largest), from the
// 3x3 Sobel derivatives of grey (CV_8UC1). CV_8UC1.
cv::Mat edgeCornerBits(const cv::Mat& grey, const Parameters& parameters, EyeScratch* scratch = nullptr);
// Canny's edges from 3x3 Sobel derivatives (CV_16SC1 each) with the L2 gradient norm: the map
// cv::Canny(dx, dy, edges, low, high, true) gives, 255 on edges and 0 elsewhere, CV_8UC1.
void cannyEdges(const cv::Mat& dx, const cv::Mat& dy, double low, double high, cv::Mat& edges);

// ---- costs.cpp --------------------------------------------------------------------------------
// What the cost stage needs of one image.
struct CostInputs {
    cv::Mat bgr;          // CV_8UC3
    cv::Mat gradient;     // CV_8UC3 (Paper only)
    cv::Mat windowMask;   // CV_8UC1 (Paper, left image only)
    // The Census codes: the whole image's, or (the reference needs the former) made row by row
    // as the costs need them, the inputs' column 0 being the encoder's column censusFirstColumn.
    const CensusImage* census = nullptr;
    const CensusEncoder* encoder = nullptr;
    int censusFirstColumn = 0;
};
// Called with y as soon as row y of the cost volume is complete, on the thread that computed it, so
// that the next stages can start on the row while it is still in cache.
using CostRowHook = std::function<void(int y)>;
// Paper: C = (1 - exp(-C_cen/λcen)) + (1 - exp(-C_AD/λAD)) + (1 - exp(-C_grad/λgrad)).
void paperCost(const CostInputs& left, const CostInputs& right, const Parameters& parameters, CostVolume& out,
               const CostRowHook& rowDone = {});
void paperCostReference(const CostInputs& left, const CostInputs& right, const Parameters& parameters,
                        CostVolume& out);
// Mei: C = (1 - exp(-C_census/λcensus)) + (1 - exp(-C_AD/λAD)), C_AD the mean over R,G,B.
void adCensusCost(const CostInputs& left, const CostInputs& right, const Parameters& parameters, CostVolume& out,
                  const CostRowHook& rowDone = {});
void adCensusCostReference(const CostInputs& left, const CostInputs& right, const Parameters& parameters,
                           CostVolume& out);
// Cost of a pair where neither pixel lies inside the other image (x - d < 0), per method.
inline constexpr std::uint16_t kPaperInvalidCost = 3 * kCostScale;
inline constexpr std::uint16_t kAdCensusInvalidCost = 2 * kCostScale;
// The right view's matching costs from the left view's: right pixel x at disparity d is left pixel
// x + d at d, the same pair. Stored mirrored (column W-1-x), so that the right view is the left
// view of the mirrored pair and every later stage applies unchanged; pairs whose left pixel lies
// outside the image (x + d >= W) cost `invalid`.
void rightViewCosts(const CostVolume& left, std::uint16_t invalid, CostVolume& mirroredRight);
// The same for row y alone, into a volume already created at the left one's size.
void rightViewCostsRow(const CostVolume& left, std::uint16_t invalid, CostVolume& mirroredRight, int y);

// ---- cross_aggregation.cpp --------------------------------------------------------------------
// D_c: the largest absolute difference over the colour channels.
int colourDistance(const cv::Vec3b& a, const cv::Vec3b& b);
void computeCrossArms(const cv::Mat& bgr, const Parameters& parameters, CrossArms& arms);
void computeCrossArmsReference(const cv::Mat& bgr, const Parameters& parameters, CrossArms& arms);
// `iterations` times, alternating the order (even iterations horizontal then vertical, odd ones
// vertical then horizontal): arm sums along one axis, then the count-weighted sum of those along
// the other, divided by the region's pixel count. In place.
// rowsDone: meanAlongRow has already run on every row (the first pass of the first iteration).
void aggregateCross(const CrossArms& arms, int iterations, CostVolume& costs, bool rowsDone = false);
// The first pass of aggregateCross for row y alone, in place: the plain mean along each pixel's
// horizontal arm. The matcher runs it on each row as the cost stage completes it, while the row is
// still in cache, instead of reading the whole volume back from memory.
void meanAlongRow(const CrossArms& arms, CostVolume& costs, int y);
void aggregateCrossReference(const CrossArms& arms, int iterations, CostVolume& costs);

// ---- scanline_optimisation.cpp ----------------------------------------------------------------
struct ScanlinePenalties {
    std::uint16_t p1[3];  // both colour differences < tau, exactly one, neither
    std::uint16_t p2[3];
    int tau = 0;
};
ScanlinePenalties scanlinePenalties(const Parameters& parameters);
// Which of the three cases applies for D1 = D_c(p, p-r), D2 = D_c(p-r, p-2r).
int penaltyCase(int d1, int d2, int tau);
// sum(p, d) = sum over the directions r of L_r(p, d): all 8, or the 4 along the axes (no
// diagonals). With 8, a volume the size of costs is needed as scratch: `spare` when given (the
// caller may lend one it is not using), else one kept per thread. `disparity`, when given, receives
// the left view's winner-take-all of the sum (as winnerTakesAll), taken as each pixel's sum is
// completed, CV_16SC1.
void aggregateScanlines(const CostVolume& costs, const cv::Mat& bgr, const ScanlinePenalties& penalties,
                        CostVolume& sum, int directions = 8, CostVolume* spare = nullptr,
                        cv::Mat* disparity = nullptr);
void aggregateScanlinesReference(const CostVolume& costs, const cv::Mat& bgr, const ScanlinePenalties& penalties,
                                 CostVolume& sum, int directions = 8);
// One step of one direction: L(d) from the previous pixel's Lprev. Exposed for tests.
void scanlineStep(const std::uint16_t* cost, const std::uint16_t* previous, int disparities, std::uint16_t p1,
                  std::uint16_t p2, std::uint16_t* out);

// ---- wta.cpp ----------------------------------------------------------------------------------
// Winner-take-all of the left view, and of the right view from the same volume
// (D_R(x) = argmin_d cost(x + d, d)). CV_16SC1. (The left view alone comes out of
// aggregateScanlines.)
void winnerTakesAll(const CostVolume& costs, cv::Mat& leftDisparity, cv::Mat& rightDisparity);
void winnerTakesAllReference(const CostVolume& costs, cv::Mat& leftDisparity, cv::Mat& rightDisparity);

// ---- refinement.cpp ---------------------------------------------------------------------------
enum PixelLabel : std::uint8_t { kReliable = 0, kOccluded = 1, kMismatched = 2 };
// Marks inconsistent pixels (|D_L(p) - D_R(p - D_L(p))| > maxDifference) as outliers and tells
// occlusions from mismatches as Mei does. Returns labels, CV_8UC1.
cv::Mat leftRightCheck(const cv::Mat& leftDisparity, const cv::Mat& rightDisparity, int disparities,
                       int maxDifference);
// Iterative region voting over the cross support regions; outliers that win a vote become
// reliable. Returns how many pixels were filled. The reference builds every outlier's histogram
// pixel by pixel (refinement.cpp); the optimised kernel from column prefix sums
// (region_voting.cpp). They give the same integers.
int regionVoting(const CrossArms& arms, const Parameters& parameters, cv::Mat& disparity, cv::Mat& labels);
int regionVotingReference(const CrossArms& arms, const Parameters& parameters, cv::Mat& disparity, cv::Mat& labels);
// The iterations both voting kernels share, Jacobi style: each pass reads the previous pass's
// maps (before, labelsBefore) and writes disparity and labels, so the result does not depend on
// the order (or the thread) in which pixels are visited. pass(before, labelsBefore, filled) adds
// the pixels it fills to filled[stripe]. Stops early when a pass fills nothing.
template <class Pass>
int iterateVoting(int iterations, cv::Mat& disparity, cv::Mat& labels, const Pass& pass) {
    int filledTotal = 0;
    for (int iteration = 0; iteration < iterations; ++iteration) {
        const cv::Mat before = disparity.clone();
        const cv::Mat labelsBefore = labels.clone();
        std::vector<int> filledPerStripe(kStripes, 0);
        pass(before, labelsBefore, filledPerStripe);
        int filled = 0;
        for (int f : filledPerStripe) filled += f;
        filledTotal += filled;
        if (filled == 0) break;
    }
    return filledTotal;
}
// Fills the remaining outliers along their row: occluded from the background (left) side,
// mismatched with the smaller of the nearest reliable left and right disparities.
void interpolateOutliers(cv::Mat& disparity, cv::Mat& labels);
// Mei's depth-discontinuity adjustment: a pixel on a disparity edge (a horizontal neighbour more
// than one pixel away) takes the disparity of the neighbour on either side whose aggregated cost
// at this pixel is lower than its own. Returns how many pixels changed.
int adjustDiscontinuities(const CostVolume& costs, cv::Mat& disparity);
// Sub-pixel disparity from the aggregated costs around each integer disparity. CV_32FC1. The
// volume's index d is disparity d + band.min; a pixel at the band's edge (index
// band.width() - 1, or 0 when band.min > 0) becomes kInvalidDisparity (DisparityRange explains).
cv::Mat subpixelRefine(const cv::Mat& disparity, const CostVolume& costs, DisparityRange band);
// Removes what is left of pixel locking: Gauss-Newton steps of 1-D Lucas-Kanade on the grey
// images (zero-mean over a (2r+1)^2 window), starting from the fitted disparity and staying
// within ±maxChange of it. greyLeft, greyRight: CV_32FC1. `scratch`: three images of their size,
// kept by the caller between pairs (EyeScratch says why); none: the call's own.
struct RefinementScratch {
    cv::Mat slope, derivative, derivativeSlope;
};
void refineSubpixelByIntensity(const cv::Mat& greyLeft, const cv::Mat& greyRight, int radius, int iterations,
                               float maxChange, cv::Mat& disparity, RefinementScratch* scratch = nullptr);
// The same, one window sample at a time; the optimised kernel sums in another order, so the two
// agree to float rounding, not bit for bit.
void refineSubpixelByIntensityReference(const cv::Mat& greyLeft, const cv::Mat& greyRight, int radius,
                                        int iterations, float maxChange, cv::Mat& disparity);
// The fit used by subpixelRefine: offset in (-0.5, 0.5) from the costs at d-1, d, d+1.
float subpixelOffset(int costMinus, int cost, int costPlus);

}  // namespace icewatch::stereo::detail
