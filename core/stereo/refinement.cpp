// Disparity refinement after the winner-take-all, following Mei et al. 2011 as the seed paper
// does: left-right check, iterative region voting inside the cross support regions,
// interpolation of what is left, depth-discontinuity adjustment, sub-pixel refinement.
//
// Sub-pixel, in two steps, because the ice volume is a mean of sub-pixel differences (see
// docs/HBVCAM.md in the shared folder) and so systematic bias matters more than noise:
// 1. On the aggregated cost, the equiangular ("V") fit of Shimizu and Okutomi, not the parabola:
//    the costs are sums of robust, L1-like terms with a kink at the minimum, and a parabola
//    through a kink pulls estimates towards the integer harder (measured on a synthetic
//    fractional shift: mean error up to 0.25 px with the parabola, 0.18 px with the V fit).
// 2. Even the V fit stays pixel-locked, because Census distances and saturated exp() terms
//    change in steps with a sub-pixel shift. So the fitted value only starts a 1-D Lucas-Kanade
//    refinement on the grey images: Gauss-Newton steps minimising the zero-mean SSD of a small
//    window with the right image linearly interpolated, which has no preference for integers.
//    The matcher tests check the mean error at several fractions of a pixel.
#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/imgproc.hpp>

#include "core/common/simd.hpp"
#include "core/stereo/matcher.hpp"
#include "core/stereo/stages.hpp"

namespace icewatch::stereo::detail {

cv::Mat leftRightCheck(const cv::Mat& leftDisparity, const cv::Mat& rightDisparity, int disparities,
                       int maxDifference) {
    CV_Assert(leftDisparity.type() == CV_16SC1 && rightDisparity.type() == CV_16SC1);
    cv::Mat labels(leftDisparity.size(), CV_8UC1);
    const int width = leftDisparity.cols;
    forEachStripe(leftDisparity.rows, [&](int, int begin, int end) {
        for (int y = begin; y < end; ++y) {
            const auto* left = leftDisparity.ptr<std::int16_t>(y);
            const auto* right = rightDisparity.ptr<std::int16_t>(y);
            auto* label = labels.ptr<std::uint8_t>(y);
            for (int x = 0; x < width; ++x) {
                const int d = left[x];
                if (d >= 0 && x - d >= 0 && std::abs(d - right[x - d]) <= maxDifference) {
                    label[x] = kReliable;
                    continue;
                }
                // Mei: if the epipolar line offers some consistent match (a right pixel that
                // maps back here), the pixel was seen by both eyes and merely mismatched;
                // otherwise it is hidden from the right eye.
                label[x] = kOccluded;
                for (int t = 0; t < std::min(disparities, x + 1); ++t) {
                    if (right[x - t] == t) {
                        label[x] = kMismatched;
                        break;
                    }
                }
            }
        }
    });
    return labels;
}

int regionVotingReference(const CrossArms& arms, const Parameters& parameters, cv::Mat& disparity, cv::Mat& labels) {
    CV_Assert(disparity.type() == CV_16SC1 && labels.type() == CV_8UC1);
    double maxValue = 0.0;
    cv::minMaxLoc(disparity, nullptr, &maxValue);
    const int bins = static_cast<int>(maxValue) + 1;
    return iterateVoting(parameters.votingIterations, disparity, labels, [&](const cv::Mat& before,
                                                                             const cv::Mat& labelsBefore,
                                                                             std::vector<int>& filledPerStripe) {
        forEachStripe(disparity.rows, [&](int stripe, int begin, int end) {
            std::vector<int> histogram(static_cast<std::size_t>(bins));
            for (int y = begin; y < end; ++y)
                for (int x = 0; x < disparity.cols; ++x) {
                    if (labelsBefore.at<std::uint8_t>(y, x) == kReliable) continue;
                    std::fill(histogram.begin(), histogram.end(), 0);
                    int reliable = 0;
                    for (int yy = y - arms.up.at<std::uint8_t>(y, x); yy <= y + arms.down.at<std::uint8_t>(y, x); ++yy) {
                        const auto* d = before.ptr<std::int16_t>(yy);
                        const auto* l = labelsBefore.ptr<std::uint8_t>(yy);
                        const int x0 = x - arms.left.at<std::uint8_t>(yy, x), x1 = x + arms.right.at<std::uint8_t>(yy, x);
                        for (int xx = x0; xx <= x1; ++xx) {
                            if (l[xx] != kReliable) continue;
                            ++histogram[static_cast<std::size_t>(d[xx])];
                            ++reliable;
                        }
                    }
                    if (reliable <= parameters.votingMinCount) continue;
                    const auto top = std::max_element(histogram.begin(), histogram.end());
                    if (*top <= parameters.votingMinRatio * reliable) continue;
                    disparity.at<std::int16_t>(y, x) = static_cast<std::int16_t>(top - histogram.begin());
                    labels.at<std::uint8_t>(y, x) = kReliable;
                    ++filledPerStripe[static_cast<std::size_t>(stripe)];
                }
        });
    });
}

void interpolateOutliers(cv::Mat& disparity, cv::Mat& labels) {
    CV_Assert(disparity.type() == CV_16SC1 && labels.type() == CV_8UC1);
    const int width = disparity.cols;
    forEachStripe(disparity.rows, [&](int, int begin, int end) {
        std::vector<int> leftValue(static_cast<std::size_t>(width)), rightValue(static_cast<std::size_t>(width));
        for (int y = begin; y < end; ++y) {
            auto* d = disparity.ptr<std::int16_t>(y);
            auto* l = labels.ptr<std::uint8_t>(y);
            int last = -1;
            for (int x = 0; x < width; ++x) {
                if (l[x] == kReliable) last = d[x];
                leftValue[static_cast<std::size_t>(x)] = last;
            }
            last = -1;
            for (int x = width - 1; x >= 0; --x) {
                if (l[x] == kReliable) last = d[x];
                rightValue[static_cast<std::size_t>(x)] = last;
            }
            for (int x = 0; x < width; ++x) {
                if (l[x] == kReliable) continue;
                const int a = leftValue[static_cast<std::size_t>(x)], b = rightValue[static_cast<std::size_t>(x)];
                int value;
                if (a < 0 || b < 0) {
                    value = std::max(a, b);  // only one side exists (or none: stays invalid)
                } else if (l[x] == kOccluded) {
                    // Hidden from the right eye by something nearer on its right: the surface it
                    // belongs to continues from the left.
                    value = a;
                } else {
                    value = std::min(a, b);
                }
                d[x] = static_cast<std::int16_t>(value);
            }
        }
    });
}

int adjustDiscontinuities(const CostVolume& costs, cv::Mat& disparity) {
    CV_Assert(disparity.type() == CV_16SC1);
    // Reads the map as it was, so the result does not depend on the visiting order.
    const cv::Mat before = disparity.clone();
    const int width = disparity.cols;
    std::vector<int> changedPerStripe(kStripes, 0);
    forEachStripe(disparity.rows, [&](int stripe, int begin, int end) {
        for (int y = begin; y < end; ++y) {
            const auto* d = before.ptr<std::int16_t>(y);
            auto* out = disparity.ptr<std::int16_t>(y);
            for (int x = 1; x + 1 < width; ++x) {
                const int own = d[x];
                if (own < 0) continue;
                // On a disparity edge when either horizontal neighbour jumps by more than a pixel.
                if (std::abs(d[x - 1] - own) <= 1 && std::abs(d[x + 1] - own) <= 1) continue;
                const std::uint16_t* c = costs.at(x, y);
                const int valid = std::min(costs.disparities, x + 1);
                int best = own, bestCost = c[own];
                for (const int candidate : {static_cast<int>(d[x - 1]), static_cast<int>(d[x + 1])}) {
                    if (candidate < 0 || candidate >= valid || c[candidate] >= bestCost) continue;
                    best = candidate;
                    bestCost = c[candidate];
                }
                if (best != own) {
                    out[x] = static_cast<std::int16_t>(best);
                    ++changedPerStripe[static_cast<std::size_t>(stripe)];
                }
            }
        }
    });
    int changed = 0;
    for (int c : changedPerStripe) changed += c;
    return changed;
}

float subpixelOffset(int costMinus, int cost, int costPlus) {
    // Equiangular fit: two lines of equal and opposite slope through the three costs, the slope
    // taken from the steeper side.
    const int steeper = std::max(costMinus, costPlus) - cost;
    if (steeper <= 0) return 0.0f;
    const float offset = 0.5f * static_cast<float>(costMinus - costPlus) / static_cast<float>(steeper);
    return std::clamp(offset, -0.5f, 0.5f);
}

cv::Mat subpixelRefine(const cv::Mat& disparity, const CostVolume& costs, DisparityRange band) {
    CV_Assert(band.width() == costs.disparities);
    cv::Mat refined(disparity.size(), CV_32FC1);
    const int last = costs.disparities - 1;
    const int firstOnEdge = band.min > 0 ? 0 : -1;  // disparity 0 has nothing beyond it
    forEachStripe(disparity.rows, [&](int, int begin, int end) {
        for (int y = begin; y < end; ++y) {
            const auto* d = disparity.ptr<std::int16_t>(y);
            auto* out = refined.ptr<float>(y);
            for (int x = 0; x < disparity.cols; ++x) {
                if (d[x] < 0 || d[x] == last || d[x] == firstOnEdge) {
                    out[x] = kInvalidDisparity;
                    continue;
                }
                // The band's offset in integers first: the float sum is then the full range's.
                out[x] = static_cast<float>(d[x] + band.min);
                if (d[x] < 1 || d[x] + 1 >= std::min(costs.disparities, x + 1)) continue;
                const std::uint16_t* c = costs.at(x, y) + d[x];
                // Only a local minimum has a shape to fit; filled-in pixels may sit elsewhere.
                if (c[0] > c[-1] || c[0] > c[1]) continue;
                out[x] += subpixelOffset(c[-1], c[0], c[1]);
            }
        }
    });
    return refined;
}

namespace {

// 255 where the (2r+1)² window around a pixel holds a disparity more than a pixel from the
// centre's: the window's largest and smallest values (dilation and erosion) against the centre.
// disparity may be a band of rows of a larger map (straddles the same band of a map of its
// size): OpenCV's filters read the rows around a submatrix, so a band's windows see them.
void depthEdgeWindows(const cv::Mat& disparity, int radius, cv::Mat straddles) {
    const cv::Mat box = cv::getStructuringElement(cv::MORPH_RECT, {2 * radius + 1, 2 * radius + 1});
    cv::Mat largest, smallest;
    cv::dilate(disparity, largest, box, {-1, -1}, 1, cv::BORDER_REPLICATE);
    cv::erode(disparity, smallest, box, {-1, -1}, 1, cv::BORDER_REPLICATE);
    constexpr int kLanes = cv::v_float32::nlanes;
    const cv::v_float32 one = cv::vx_setall_f32(1.0f);
    for (int y = 0; y < disparity.rows; ++y) {
        const float* centre = disparity.ptr<float>(y);
        const float* hi = largest.ptr<float>(y);
        const float* lo = smallest.ptr<float>(y);
        auto* out = straddles.ptr<std::uint8_t>(y);
        int x = 0;
        for (; x + 4 * kLanes <= disparity.cols; x += 4 * kLanes) {
            cv::v_uint32 straddle[4];
            for (int k = 0; k < 4; ++k) {
                const cv::v_float32 c = cv::vx_load(centre + x + k * kLanes);
                straddle[k] = cv::v_reinterpret_as_u32((cv::vx_load(hi + x + k * kLanes) - c > one) |
                                                       (c - cv::vx_load(lo + x + k * kLanes) > one));
            }
            cv::v_store(out + x, cv::v_pack_b(straddle[0], straddle[1], straddle[2], straddle[3]));
        }
        for (; x < disparity.cols; ++x) {
            out[x] = (hi[x] - centre[x] > 1.0f || centre[x] - lo[x] > 1.0f) ? 255 : 0;
        }
    }
}

cv::Mat depthEdgeWindows(const cv::Mat& disparity, int radius) {
    cv::Mat straddles(disparity.size(), CV_8UC1);
    depthEdgeWindows(disparity, radius, straddles);
    return straddles;
}

// Window sums of one Gauss-Newton step: residual e = I_L - I_R(x - d) and right x-derivative g.
struct WindowSums {
    float e = 0.0f, g = 0.0f, eg = 0.0f, gg = 0.0f;
};

// The reference kernel's pixel loop. sums(x, y, x0, t) returns the window sums with the right
// image sampled at x0 + t + dx (0 <= t < 1); everything else (which pixels, when to stop, what
// to keep) is decided here. The optimised kernel takes the same decisions on vector lanes, with
// the same operations.
template <class Sums>
void refineEachPixel(int width, int height, int radius, int iterations, float maxChange, cv::Mat& disparity,
                     const Sums& sums) {
    const int side = 2 * radius + 1;
    const float count = static_cast<float>(side * side);
    // The window must see one surface: where it straddles a depth edge (a disparity in it more
    // than a pixel from the centre's) the SSD mixes the two surfaces' shifts and would drag the
    // centre towards the other one, so the cost fit stands there. Decided for every pixel before
    // any is refined: the rows being refined are changing.
    const cv::Mat straddles = depthEdgeWindows(disparity, radius);
    forEachStripe(height, [&](int, int begin, int end) {
        for (int y = begin; y < end; ++y) {
            if (y < radius || y + radius >= height) continue;
            float* out = disparity.ptr<float>(y);
            const std::uint8_t* edge = straddles.ptr<std::uint8_t>(y);
            for (int x = radius; x + radius < width; ++x) {
                const float start = out[x];
                if (start < 0.0f || edge[x] != 0) continue;
                float d = start;
                bool ok = true;
                for (int iteration = 0; iteration < iterations && ok; ++iteration) {
                    const float xr = static_cast<float>(x) - d;
                    const int x0 = static_cast<int>(std::floor(xr));
                    const float t = xr - static_cast<float>(x0);
                    if (x0 - radius - 1 < 0 || x0 + radius + 2 >= width) {
                        ok = false;
                        break;
                    }
                    const WindowSums w = sums(x, y, x0, t);
                    // Zero-mean residual and gradient: a brightness offset between the eyes
                    // must not move the estimate.
                    const float varG = w.gg - w.g * w.g / count;
                    if (varG < 1e-3f * count) {
                        ok = false;  // no texture: the fit is all there is
                        break;
                    }
                    const float covEG = w.eg - w.e * w.g / count;
                    // I_L(x) = I_R(x - d - δ) ≈ I_R - δ g: the residual e = -δ g.
                    const float step = covEG / varG;
                    d -= step;
                    if (std::abs(step) < 0.005f) break;  // converged far below any use of it
                }
                if (ok && std::abs(d - start) <= maxChange) out[x] = d;
            }
        }
    });
}

// a * b + c rounded as cv::v_fma rounds it (fused where the vector instruction is), so that a
// pixel's sums do not depend on whether its window was summed in a vector lane or alone.
inline float fmaAsVector(float a, float b, float c) {
#if CV_FMA3 || (CV_NEON && defined(__aarch64__))
    return std::fma(a, b, c);
#else
    return a * b + c;
#endif
}

}  // namespace

void refineSubpixelByIntensityReference(const cv::Mat& greyLeft, const cv::Mat& greyRight, int radius,
                                        int iterations, float maxChange, cv::Mat& disparity) {
    CV_Assert(greyLeft.type() == CV_32FC1 && greyRight.type() == CV_32FC1 && disparity.type() == CV_32FC1);
    refineEachPixel(greyLeft.cols, greyLeft.rows, radius, iterations, maxChange, disparity,
                    [&](int x, int y, int x0, float t) {
                        // Right samples at x0 + dx + t and their x-derivative, linearly interpolated.
                        WindowSums w;
                        for (int dy = -radius; dy <= radius; ++dy) {
                            const float* left = greyLeft.ptr<float>(y + dy);
                            const float* row = greyRight.ptr<float>(y + dy);
                            for (int dx = -radius; dx <= radius; ++dx) {
                                const int i = x0 + dx;
                                const float value = row[i] + t * (row[i + 1] - row[i]);
                                const float gradient = 0.5f * ((row[i + 1] - row[i - 1]) +
                                                               t * ((row[i + 2] - row[i]) - (row[i + 1] - row[i - 1])));
                                const float e = left[x + dx] - value;
                                w.e += e;
                                w.g += gradient;
                                w.eg += e * gradient;
                                w.gg += gradient * gradient;
                            }
                        }
                        return w;
                    });
}

namespace {

// What the optimised kernel reads besides the two images, one row per image row: the right
// image's slope s(i) = R(i+1) - R(i), its x-derivative g(i) = (R(i+1) - R(i-1)) / 2 and that
// one's slope g(i+1) - g(i). The interpolated sample and derivative at x0 + t are then
// R(x0) + t s(x0) and g(x0) + t (g(x0+1) - g(x0)): the reference's expressions rearranged
// (halving is exact, so only the reference's own rounding differs).
struct RightRows {
    const float* value;
    const float* slope;
    const float* derivative;
    const float* derivativeSlope;
};

// The window sums of kLanes pixels, a pixel per lane.
struct LaneSums {
    cv::v_float32 e, g, eg, gg;
};

// The window sums of kLanes neighbouring pixels x + p at once, each lane summing in the
// reference's order. Lane p's window starts at base + p, or at base + p - 1 where shifted (all
// bits set): neighbouring pixels' disparities round up to the same integer or to neighbouring
// ones, and both are then whole-vector loads. t as in refineEachPixel. kRadius > 0 fixes the
// radius at compile time (the default window), so that the loops unroll.
template <bool kAnyShifted, int kRadius>
LaneSums windowSumsOfLanes(const cv::Mat& left, const RightRows* rows, int x, int y, int base, int anyRadius,
                           const cv::v_float32& t, const cv::v_float32& shifted) {
    const int radius = kRadius > 0 ? kRadius : anyRadius;
    const int side = 2 * radius + 1;
    LaneSums sums{cv::vx_setzero_f32(), cv::vx_setzero_f32(), cv::vx_setzero_f32(), cv::vx_setzero_f32()};
    for (int dy = -radius; dy <= radius; ++dy) {
        const float* l = left.ptr<float>(y + dy) + x - radius;
        const RightRows& row = rows[dy + radius];
        const int at = base - radius;
        for (int c = 0; c < side; ++c) {
            cv::v_float32 r = cv::vx_load(row.value + at + c), s = cv::vx_load(row.slope + at + c);
            cv::v_float32 g = cv::vx_load(row.derivative + at + c), gs = cv::vx_load(row.derivativeSlope + at + c);
            if constexpr (kAnyShifted) {
                r = cv::v_select(shifted, cv::vx_load(row.value + at + c - 1), r);
                s = cv::v_select(shifted, cv::vx_load(row.slope + at + c - 1), s);
                g = cv::v_select(shifted, cv::vx_load(row.derivative + at + c - 1), g);
                gs = cv::v_select(shifted, cv::vx_load(row.derivativeSlope + at + c - 1), gs);
            }
            const cv::v_float32 value = cv::v_fma(t, s, r);
            const cv::v_float32 gradient = cv::v_fma(t, gs, g);
            const cv::v_float32 e = cv::vx_load(l + c) - value;
            sums.e += e;
            sums.g += gradient;
            sums.eg = cv::v_fma(e, gradient, sums.eg);
            sums.gg = cv::v_fma(gradient, gradient, sums.gg);
        }
    }
    return sums;
}

template <int kRadius>
LaneSums windowSumsOfLanes(bool anyShifted, const cv::Mat& left, const RightRows* rows, int x, int y, int base,
                           int radius, const cv::v_float32& t, const cv::v_float32& shifted) {
    return anyShifted ? windowSumsOfLanes<true, kRadius>(left, rows, x, y, base, radius, t, shifted)
                      : windowSumsOfLanes<false, kRadius>(left, rows, x, y, base, radius, t, shifted);
}

// The same sums for one pixel whose window starts at x0, for the pixels a group cannot take.
WindowSums windowSumsOfPixel(const cv::Mat& left, const RightRows* rows, int x, int y, int x0, int radius, float t) {
    WindowSums w;
    for (int dy = -radius; dy <= radius; ++dy) {
        const float* l = left.ptr<float>(y + dy);
        const RightRows& row = rows[dy + radius];
        for (int dx = -radius; dx <= radius; ++dx) {
            const int i = x0 + dx;
            const float value = fmaAsVector(t, row.slope[i], row.value[i]);
            const float gradient = fmaAsVector(t, row.derivativeSlope[i], row.derivative[i]);
            const float e = l[x + dx] - value;
            w.e += e;
            w.g += gradient;
            w.eg = fmaAsVector(e, gradient, w.eg);
            w.gg = fmaAsVector(gradient, gradient, w.gg);
        }
    }
    return w;
}

}  // namespace

// The optimised kernel: a vector lane per pixel, kLanes neighbouring pixels of a row at a time
// (cv::v_float32), each lane summing its own window in the reference's order, so that no lane is
// wasted on a window narrower than a vector and no horizontal reduction is needed. The steps,
// stopping rules and max-change rule of refineEachPixel run on the lanes too, with the same
// operations. A lane's window starts at x0 = x - ceil(d); neighbouring pixels on one surface have
// disparities within a pixel or so of each other, so their windows start at consecutive columns
// (one vector load) or one column earlier (a second load and a select). Pixels further off, the
// last pixels of a row and groups whose loads would leave the image are summed one at a time with
// the same arithmetic.
void refineSubpixelByIntensity(const cv::Mat& greyLeft, const cv::Mat& greyRight, int radius, int iterations,
                               float maxChange, cv::Mat& disparity, RefinementScratch* scratch) {
    CV_Assert(greyLeft.type() == CV_32FC1 && greyRight.type() == CV_32FC1 && disparity.type() == CV_32FC1);
    CV_Assert(greyLeft.size() == greyRight.size() && greyLeft.size() == disparity.size() && radius >= 1);
    constexpr int kLanes = cv::v_float32::nlanes;
    const int width = greyLeft.cols, height = greyLeft.rows;
    const int side = 2 * radius + 1;
    const float count = static_cast<float>(side * side);
    const cv::Mat& left = greyLeft;
    const cv::Mat& right = greyRight;

    // Reallocated only when the size changes. The stripes run on other threads and see these
    // buffers through the references.
    RefinementScratch own;
    RefinementScratch& buffers = scratch ? *scratch : own;
    cv::Mat& slope = buffers.slope;
    cv::Mat& derivative = buffers.derivative;
    cv::Mat& derivativeSlope = buffers.derivativeSlope;
    for (cv::Mat* m : {&slope, &derivative, &derivativeSlope}) m->create(height, width, CV_32FC1);
    cv::Mat straddles(disparity.size(), CV_8UC1);
    // Before any pixel is refined, as in refineEachPixel, but a band of rows per stripe.
    forEachStripe(height, [&](int, int begin, int end) {
        if (begin < end) {
            const cv::Rect band(0, begin, width, end - begin);
            depthEdgeWindows(disparity(band), radius, straddles(band));
        }
        for (int y = begin; y < end; ++y) {
            const float* r = right.ptr<float>(y);
            float* s = slope.ptr<float>(y);
            float* g = derivative.ptr<float>(y);
            float* gs = derivativeSlope.ptr<float>(y);
            const cv::v_float32 half = cv::vx_setall_f32(0.5f);
            int x = 1;
            for (; x + kLanes < width; x += kLanes) {
                const cv::v_float32 before = cv::vx_load(r + x - 1), after = cv::vx_load(r + x + 1);
                cv::v_store(s + x, after - cv::vx_load(r + x));
                cv::v_store(g + x, (after - before) * half);
            }
            for (; x + 1 < width; ++x) {
                s[x] = r[x + 1] - r[x];
                g[x] = 0.5f * (r[x + 1] - r[x - 1]);
            }
            // The first and last columns: no refined window reads a derivative there.
            s[0] = width > 1 ? r[1] - r[0] : 0.0f;
            s[width - 1] = 0.0f;
            g[0] = 0.0f;
            g[width - 1] = 0.0f;
            for (x = 0; x + kLanes < width; x += kLanes) {
                cv::v_store(gs + x, cv::vx_load(g + x + 1) - cv::vx_load(g + x));
            }
            for (; x + 1 < width; ++x) gs[x] = g[x + 1] - g[x];
            gs[width - 1] = 0.0f;
        }
    });

    std::int32_t laneValues[kLanes];
    for (int p = 0; p < kLanes; ++p) laneValues[p] = p;
    const cv::v_int32 lane = cv::vx_load(laneValues);
    const cv::v_float32 zero = cv::vx_setzero_f32(), vCount = cv::vx_setall_f32(count);
    const cv::v_float32 minVariance = cv::vx_setall_f32(1e-3f * count), converged = cv::vx_setall_f32(0.005f);
    const cv::v_float32 vMaxChange = cv::vx_setall_f32(maxChange);
    forEachStripe(height, [&](int, int begin, int end) {
        std::vector<RightRows> rows(static_cast<std::size_t>(side));
        for (int y = std::max(begin, radius); y < std::min(end, height - radius); ++y) {
            for (int dy = -radius; dy <= radius; ++dy) {
                rows[static_cast<std::size_t>(dy + radius)] =
                    RightRows{right.ptr<float>(y + dy), slope.ptr<float>(y + dy), derivative.ptr<float>(y + dy),
                              derivativeSlope.ptr<float>(y + dy)};
            }
            float* out = disparity.ptr<float>(y);
            const std::uint8_t* edge = straddles.ptr<std::uint8_t>(y);
            for (int x = radius; x + radius < width; x += kLanes) {
                const int lanes = std::min(kLanes, width - radius - x);
                cv::v_float32 start, refinable;
                if (lanes == kLanes) {
                    start = cv::vx_load(out + x);
                    refinable = cv::v_reinterpret_as_f32(cv::vx_load_expand_q(edge + x) == cv::vx_setzero_u32());
                } else {
                    // Lanes past the row's last pixel start invalid and stay idle.
                    float startValues[kLanes];
                    std::int32_t refinableValues[kLanes];
                    for (int p = 0; p < kLanes; ++p) {
                        startValues[p] = p < lanes ? out[x + p] : -1.0f;
                        refinableValues[p] = p < lanes && edge[x + p] == 0 ? -1 : 0;
                    }
                    start = cv::vx_load(startValues);
                    refinable = cv::v_reinterpret_as_f32(cv::vx_load(refinableValues));
                }
                cv::v_float32 d = start;
                cv::v_float32 active = (start >= zero) & refinable;
                cv::v_float32 ok = active;
                const cv::v_int32 column = cv::vx_setall_s32(x) + lane;
                for (int iteration = 0; iteration < iterations && cv::v_check_any(active); ++iteration) {
                    // As refineEachPixel: where the window starts, and whether it stays inside.
                    const cv::v_float32 xr = cv::v_cvt_f32(column) - d;
                    const cv::v_int32 x0 = cv::v_floor(xr);
                    const cv::v_float32 t = xr - cv::v_cvt_f32(x0);
                    const cv::v_float32 inside = cv::v_reinterpret_as_f32(
                        (x0 >= cv::vx_setall_s32(radius + 1)) & (x0 < cv::vx_setall_s32(width - radius - 2)));
                    ok &= inside | ~active;
                    active &= inside;
                    if (!cv::v_check_any(active)) break;
                    // Where each window starts relative to its lane; the lanes starting at
                    // highest + p or one column earlier go together, as whole vectors from
                    // highest - radius - 1 to highest + kLanes - 1 + radius.
                    const cv::v_int32 activeInt = cv::v_reinterpret_as_s32(active);
                    const cv::v_int32 relative = x0 - lane;
                    const int highest = cv::v_reduce_max(
                        cv::v_select(activeInt, relative, cv::vx_setall_s32(std::numeric_limits<int>::min())));
                    const bool loadable = lanes == kLanes && highest - radius - 1 >= 0 && highest + kLanes + radius <= width;
                    const cv::v_int32 behind = cv::vx_setall_s32(highest) - relative;
                    const cv::v_int32 together =
                        loadable ? activeInt & (behind <= cv::vx_setall_s32(1)) : cv::vx_setzero_s32();
                    const cv::v_float32 shifted = cv::v_reinterpret_as_f32(together & (behind == cv::vx_setall_s32(1)));
                    LaneSums w{zero, zero, zero, zero};
                    if (cv::v_check_any(together)) {
                        w = radius == 2 ? windowSumsOfLanes<2>(cv::v_check_any(shifted), left, rows.data(), x, y,
                                                               highest, radius, t, shifted)
                                        : windowSumsOfLanes<0>(cv::v_check_any(shifted), left, rows.data(), x, y,
                                                               highest, radius, t, shifted);
                    }
                    const cv::v_int32 alone = activeInt & ~together;
                    if (cv::v_check_any(alone)) {
                        float e[kLanes], g[kLanes], eg[kLanes], gg[kLanes], tValues[kLanes];
                        std::int32_t aloneValues[kLanes], x0Values[kLanes];
                        cv::v_store(e, w.e);
                        cv::v_store(g, w.g);
                        cv::v_store(eg, w.eg);
                        cv::v_store(gg, w.gg);
                        cv::v_store(tValues, t);
                        cv::v_store(aloneValues, alone);
                        cv::v_store(x0Values, x0);
                        for (int p = 0; p < kLanes; ++p) {
                            if (aloneValues[p] == 0) continue;
                            const WindowSums sums =
                                windowSumsOfPixel(left, rows.data(), x + p, y, x0Values[p], radius, tValues[p]);
                            e[p] = sums.e;
                            g[p] = sums.g;
                            eg[p] = sums.eg;
                            gg[p] = sums.gg;
                        }
                        w = LaneSums{cv::vx_load(e), cv::vx_load(g), cv::vx_load(eg), cv::vx_load(gg)};
                    }
                    // As refineEachPixel: the zero-mean Gauss-Newton step and when to stop.
                    const cv::v_float32 varG = w.gg - w.g * w.g / vCount;
                    const cv::v_float32 textured = active & ~(varG < minVariance);
                    ok &= textured | ~active;
                    const cv::v_float32 covEG = w.eg - w.e * w.g / vCount;
                    const cv::v_float32 step = covEG / varG;
                    d = cv::v_select(textured, d - step, d);
                    active = textured & ~(cv::v_abs(step) < converged);
                }
                const cv::v_float32 keep = ok & (cv::v_abs(d - start) <= vMaxChange);
                if (lanes == kLanes) {
                    cv::v_store(out + x, cv::v_select(keep, d, start));
                } else {
                    float result[kLanes];
                    cv::v_store(result, cv::v_select(keep, d, start));
                    std::copy(result, result + lanes, out + x);
                }
            }
        }
    });
}

}  // namespace icewatch::stereo::detail
