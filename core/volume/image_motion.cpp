// Where the texture trackers start (image_motion.hpp).
#include "core/volume/image_motion.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "core/volume/match_region.hpp"
#include "core/volume/robust_statistics.hpp"

namespace icewatch::volume {

namespace {

// The texture alone (the image less its blur): a long object's shading looks alike shifted along
// it, and a change of light moves the shading, not the texture.
cv::Mat textureOf(const cv::Mat& image) {
    cv::Mat grey, blurred;
    image.convertTo(grey, CV_32F);
    cv::GaussianBlur(grey, blurred, cv::Size(), 3.0);
    return grey - blurred;
}

// A tile's texture with what stands out of it clipped: to kClipSpreads robust standard deviations
// (1.4826 · the median of |texture|; the texture is zero-mean). A highlight is tens of grey levels
// brighter than a blade's faint composite; unclipped it decides the correlation of every tile it
// crosses, and it does not move with the blade.
constexpr double kClipSpreads = 3.0;

cv::Mat clipped(const cv::Mat& texture) {
    std::vector<float> magnitudes;
    magnitudes.reserve(texture.total());
    for (int y = 0; y < texture.rows; ++y) {
        const auto* row = texture.ptr<float>(y);
        for (int x = 0; x < texture.cols; ++x) magnitudes.push_back(std::abs(row[x]));
    }
    if (magnitudes.empty()) return texture.clone();
    const double bound = kClipSpreads * kMadToSigma * median(std::move(magnitudes));
    cv::Mat out;
    cv::min(texture, bound, out);
    cv::max(out, -bound, out);
    return out;
}

// Tiles of 64 px, every 32 px: a blade's chord at 2560x720 holds one across (it is ~100 px).
constexpr int kTilePx = 64;
constexpr int kTileStepPx = 32;
// A tile counts when the object covers most of it: the sky or a fixed table beside it would pull
// its shift towards zero.
constexpr double kTileObjectShare = 0.6;
// How far around its start a tile is looked for: the ~10 px a degree adds at a blade's ends.
constexpr int kTileSearchPx = 16;
// RANSAC: a tile within this of the fitted map supports it (a tile's sub-pixel peak is not
// exact), and the map needs this many supporting tiles. A similarity, not an affine map: a
// blade's chord holds one or two rows of tiles, too few to pin a shear or a stretch across it
// (an affine fit put the corners of a turned test object 1.8 px off, a similarity 0.65 px).
constexpr double kTileInlierPx = 1.5;
constexpr int kMinTiles = 8;
// How much better than the shift a map must move the texture back to start the trackers instead.
constexpr double kMapGain = 0.1;

// The global shift's coarse level: two halvings, for a box of at least this many pixels a side.
constexpr int kCoarseLevels = 2;
constexpr int kCoarseMinBoxPx = 64;

cv::Point rounded(cv::Point2d p) { return {static_cast<int>(std::lround(p.x)), static_cast<int>(std::lround(p.y))}; }

}  // namespace

cv::Matx23d translation(cv::Point2d shift) { return {1, 0, shift.x, 0, 1, shift.y}; }

cv::Point2d mapped(const cv::Matx23d& m, cv::Point2d at) {
    return {m(0, 0) * at.x + m(0, 1) * at.y + m(0, 2), m(1, 0) * at.x + m(1, 1) * at.y + m(1, 2)};
}

namespace {

// How alike the baseline's texture and the current's moved back by `motion` are where `inside`
// (the mask over the same window) is set.
double correlationMovedBack(const cv::Mat& from, const cv::Mat& to, const cv::Mat& inside, const cv::Matx23d& motion) {
    cv::Mat movedBack;
    cv::warpAffine(to, movedBack, motion, to.size(), cv::INTER_LINEAR | cv::WARP_INVERSE_MAP, cv::BORDER_REFLECT);
    return maskedCorrelation(from, movedBack, inside);
}

// The same, tile by tile (kTilePx tiles every kTileStepPx that the object covers by
// kTileObjectShare, each its own zero-mean normalised correlation), as the median over the
// tiles: a highlight or bright ice weighs as the few tiles it covers, not by its contrast. A
// glossy blade's highlight, which stays where the light and the eyes put it while the blade
// moves, outweighed the blade's faint texture in one correlation over the whole object, and a 2 %
// zoom that held the highlight in place won over the blade's true shift. With no such tile, the
// whole object's correlation.
double medianTileCorrelation(const cv::Mat& from, const cv::Mat& to, const cv::Mat& inside, const cv::Matx23d& motion) {
    cv::Mat movedBack;
    cv::warpAffine(to, movedBack, motion, to.size(), cv::INTER_LINEAR | cv::WARP_INVERSE_MAP, cv::BORDER_REFLECT);
    std::vector<double> tiles;
    for (int y = 0; y + kTilePx <= from.rows; y += kTileStepPx)
        for (int x = 0; x + kTilePx <= from.cols; x += kTileStepPx) {
            const cv::Rect tile(x, y, kTilePx, kTilePx);
            if (cv::countNonZero(inside(tile)) < kTileObjectShare * tile.area()) continue;
            tiles.push_back(maskedCorrelation(clipped(from(tile)), clipped(movedBack(tile)), inside(tile)));
        }
    if (tiles.empty()) return maskedCorrelation(from, movedBack, inside);
    return median(std::move(tiles));
}

cv::Rect grownBox(const cv::Mat& mask, double motionPx) {
    const cv::Rect box = cv::boundingRect(mask);
    const int reach = static_cast<int>(std::ceil(motionPx)) + 2;
    return (box + cv::Size(2 * reach, 2 * reach) - cv::Point(reach, reach)) & cv::Rect(cv::Point(0, 0), mask.size());
}

// The largest distance the map moves a corner of `box`: an affine map moves no pixel of it farther.
double largestMotionPx(const cv::Matx23d& motion, const cv::Rect& box) {
    double largest = 0;
    for (const cv::Point2d corner : {cv::Point2d(box.tl()), cv::Point2d(box.br()), cv::Point2d(box.x, box.br().y),
                                     cv::Point2d(box.br().x, box.y)})
        largest = std::max(largest, cv::norm(mapped(motion, corner) - corner));
    return largest;
}

// The same map in the coordinates of a window whose corner is `origin`: q' = A q + (A o + t - o).
cv::Matx23d inWindow(const cv::Matx23d& motion, cv::Point origin) {
    const cv::Point2d shifted = mapped(motion, origin) - cv::Point2d(origin);
    return {motion(0, 0), motion(0, 1), shifted.x, motion(1, 0), motion(1, 1), shifted.y};
}

}  // namespace

cv::Point2d confirmedShift(const cv::Mat& baselineLeft, const cv::Mat& currentLeft, const cv::Mat& mask,
                           cv::Point2d shift) {
    if (cv::boundingRect(mask).empty()) return {0, 0};
    const cv::Rect grown = grownBox(mask, std::hypot(shift.x, shift.y));
    const cv::Mat from = textureOf(baselineLeft(grown)), to = textureOf(currentLeft(grown));
    const cv::Mat inside = mask(grown);
    return correlationMovedBack(from, to, inside, translation(shift)) > maskedCorrelation(from, to, inside)
               ? shift
               : cv::Point2d(0, 0);
}

namespace {

// The shift that best aligns the box at full resolution.
cv::Point2d fullResolutionShift(const cv::Mat& baselineLeft, const cv::Mat& currentLeft, const cv::Rect& box) {
    cv::Mat a, b, window;
    baselineLeft(box).convertTo(a, CV_32F);
    currentLeft(box).convertTo(b, CV_32F);
    cv::createHanningWindow(window, box.size(), CV_32F);
    return cv::phaseCorrelate(a, b, window);
}

// The same, first at a quarter of the resolution, then at full resolution around it.
cv::Point2d coarseToFineShift(const cv::Mat& baselineLeft, const cv::Mat& currentLeft, const cv::Rect& box) {
    cv::Mat a, b, window;
    baselineLeft(box).convertTo(a, CV_32F);
    currentLeft(box).convertTo(b, CV_32F);
    for (int level = 0; level < kCoarseLevels; ++level) {
        cv::pyrDown(a, a);
        cv::pyrDown(b, b);
    }
    cv::createHanningWindow(window, a.size(), CV_32F);
    const cv::Point start = rounded(cv::phaseCorrelate(a, b, window) * double(1 << kCoarseLevels));
    // Over the part of the box that stays in the image moved by it.
    const cv::Rect inner = box & (cv::Rect(cv::Point(0, 0), baselineLeft.size()) - start);
    if (inner.width < 16 || inner.height < 16) return start;
    baselineLeft(inner).convertTo(a, CV_32F);
    currentLeft(inner + start).convertTo(b, CV_32F);
    cv::createHanningWindow(window, inner.size(), CV_32F);
    const cv::Point2d residual = cv::phaseCorrelate(a, b, window);
    // A residual beyond the coarse level's own pixel is another peak: the coarse shift stands.
    return cv::norm(residual) > double(1 << kCoarseLevels) ? cv::Point2d(start) : cv::Point2d(start) + residual;
}

}  // namespace

cv::Point2d globalImageShift(const cv::Mat& baselineLeft, const cv::Mat& currentLeft, const cv::Mat& mask) {
    const cv::Rect box = cv::boundingRect(mask);
    if (box.width < 16 || box.height < 16) return {0, 0};
    const cv::Point2d full = fullResolutionShift(baselineLeft, currentLeft, box);
    if (box.width < kCoarseMinBoxPx || box.height < kCoarseMinBoxPx) return full;
    // Neither level wins everywhere. At full resolution a blade moved by (16, 11) px with rime
    // patches on it correlated best at (-71, -22), where a quarter of the resolution, the outline
    // and shading outweighing the noise, found it; a long object half covered by bright ice fooled
    // the quarter resolution (the ice's own outline) and not the full. The one that moves the
    // object's texture back closer to the baseline's is the shift.
    const cv::Point2d coarse = coarseToFineShift(baselineLeft, currentLeft, box);
    const cv::Rect grown = grownBox(mask, std::max(cv::norm(full), cv::norm(coarse)));
    const cv::Mat from = textureOf(baselineLeft(grown)), to = textureOf(currentLeft(grown)), inside = mask(grown);
    return correlationMovedBack(from, to, inside, translation(coarse)) >
                   correlationMovedBack(from, to, inside, translation(full))
               ? coarse
               : full;
}

namespace {

// Where the tile at `tile` of `from` lies in `to`, searched kTileSearchPx around `offset`: the peak
// of the zero-mean normalised correlation, refined by a parabola through its neighbours. Not a
// phase correlation: that whitens the spectrum, and a JPEG's 8x8 blocks, fixed to the image, then
// weigh as much as the texture (at quality 75 every tile of a blade disagreed, and the fit
// settled on a 20 px shift the texture's grain along the span allowed).
std::optional<cv::Point2d> tileFound(const cv::Mat& from, const cv::Mat& to, const cv::Rect& tile, cv::Point offset) {
    const cv::Rect area = cv::Rect(tile.tl() + offset - cv::Point(kTileSearchPx, kTileSearchPx),
                                   tile.size() + cv::Size(2 * kTileSearchPx, 2 * kTileSearchPx));
    if ((area & cv::Rect(cv::Point(0, 0), to.size())) != area) return std::nullopt;
    cv::Mat score;
    cv::matchTemplate(clipped(to(area)), clipped(from(tile)), score, cv::TM_CCOEFF_NORMED);
    cv::Point peak;
    cv::minMaxLoc(score, nullptr, nullptr, nullptr, &peak);
    auto vertex = [](float before, float at, float after) {
        const double curvature = before - 2.0 * at + after;
        return curvature < 0 ? 0.5 * (before - after) / curvature : 0.0;
    };
    cv::Point2d sub(peak);
    if (peak.x > 0 && peak.x + 1 < score.cols)
        sub.x += vertex(score.at<float>(peak.y, peak.x - 1), score.at<float>(peak), score.at<float>(peak.y, peak.x + 1));
    if (peak.y > 0 && peak.y + 1 < score.rows)
        sub.y += vertex(score.at<float>(peak.y - 1, peak.x), score.at<float>(peak), score.at<float>(peak.y + 1, peak.x));
    return cv::Point2d(offset) + sub - cv::Point2d(kTileSearchPx, kTileSearchPx);
}

// The similarity fitted to the tiles of the object's texture, each found again around where
// `start` puts it; none when too few tiles agree on one.
std::optional<cv::Matx23d> tileMotion(const cv::Mat& from, const cv::Mat& to, const cv::Mat& mask, const cv::Matx23d& start) {
    const cv::Rect box = cv::boundingRect(mask);
    std::vector<cv::Point2f> tilesBefore, tilesAfter;
    for (int y = box.y; y + kTilePx <= box.br().y; y += kTileStepPx)
        for (int x = box.x; x + kTilePx <= box.br().x; x += kTileStepPx) {
            const cv::Rect tile(x, y, kTilePx, kTilePx);
            if (cv::countNonZero(mask(tile)) < kTileObjectShare * tile.area()) continue;
            const cv::Point2d centre(x + 0.5 * (kTilePx - 1), y + 0.5 * (kTilePx - 1));
            const std::optional<cv::Point2d> moved = tileFound(from, to, tile, rounded(mapped(start, centre) - centre));
            if (!moved) continue;
            tilesBefore.emplace_back(centre);
            tilesAfter.emplace_back(centre + *moved);
        }
    if (static_cast<int>(tilesBefore.size()) < kMinTiles) return std::nullopt;
    std::vector<std::uint8_t> inliers;
    // Fixed RANSAC iterations and OpenCV's own fixed seed: the same images give the same map.
    const cv::Mat fitted =
        cv::estimateAffinePartial2D(tilesBefore, tilesAfter, inliers, cv::RANSAC, kTileInlierPx, 2000, 0.999, 10);
    if (fitted.empty() || cv::countNonZero(inliers) < kMinTiles) return std::nullopt;
    return cv::Matx23d(fitted);
}

}  // namespace

cv::Matx23d objectImageMotion(const cv::Mat& baselineLeft, const cv::Mat& currentLeft, const cv::Mat& mask,
                              cv::Point2d start, cv::Point2d fallback) {
    const cv::Rect box = cv::boundingRect(mask);
    if (box.width < kTilePx || box.height < kTilePx) return translation(fallback);
    const cv::Mat from = textureOf(baselineLeft), to = textureOf(currentLeft);
    // The tiles start where the global shift puts them, where the confirmed shift does and in
    // place: a wrong global peak, or a turn that decorrelates the whole box, leaves the others.
    // Each map found is refined once from tiles started where it puts them: a turned tile is
    // found again best where it is least turned against its start.
    std::vector<cv::Matx23d> candidates{translation(fallback)};
    std::vector<cv::Point> starts;
    for (const cv::Point2d s : {start, fallback, cv::Point2d(0, 0)}) {
        if (std::find(starts.begin(), starts.end(), rounded(s)) != starts.end()) continue;
        starts.push_back(rounded(s));
        const std::optional<cv::Matx23d> first = tileMotion(from, to, mask, translation(starts.back()));
        if (!first) continue;
        const std::optional<cv::Matx23d> refined = tileMotion(from, to, mask, *first);
        candidates.push_back(refined ? *refined : *first);
    }
    // The one that moves the current texture back closest to the baseline's, tile by tile; a map
    // must do so by kMapGain more than the shift, which has served on every scene that moved a
    // little: ice changes much of the texture, and a wrong map (a 2 % zoom on a blade that moved
    // 3 mm) correlated 0.47 against the shift's 0.45.
    double farthest = 0;
    for (const cv::Matx23d& m : candidates) farthest = std::max(farthest, largestMotionPx(m, box));
    const cv::Rect grown = grownBox(mask, farthest);
    const cv::Mat fromGrown = from(grown), toGrown = to(grown), inside = mask(grown);
    std::size_t best = 0;
    double bestCorrelation = -2.0;
    for (std::size_t k = 0; k < candidates.size(); ++k) {
        const double c = medianTileCorrelation(fromGrown, toGrown, inside, inWindow(candidates[k], grown.tl())) -
                         (k == 0 ? 0.0 : kMapGain);
        if (c > bestCorrelation) best = k, bestCorrelation = c;
    }
    return candidates[best];
}

}  // namespace icewatch::volume
