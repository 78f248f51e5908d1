#pragma once

#include <opencv2/core.hpp>

namespace icewatch::volume {

// Where the texture trackers start: how the object moved in the left image between the captures,
// as a map from a baseline pixel to the current one. A parked blade is rarely where it
// was: a degree of pitch or a gust bends it, and its ends then move differently by more than the
// trackers search, so one shift for the whole object leaves its ends untracked (or, when the shift
// itself is not confirmed, every patch).

// The image motion of the scene between two left images, by phase correlation inside `mask`
// (CV_8U, the region that matters).
cv::Point2d globalImageShift(const cv::Mat& baselineLeft, const cv::Mat& currentLeft, const cv::Mat& mask);

// `shift` when the texture inside `mask` looks more like the baseline's moved back by it than in
// place, zero otherwise. A pattern fixed to the image (a JPEG's 8x8 blocks over a faint texture) or
// the rest of the region's box can win the phase correlation while the object moved a pixel or
// two, and a start 25 px off leaves every patch outside its search.
cv::Point2d confirmedShift(const cv::Mat& baselineLeft, const cv::Mat& currentLeft, const cv::Mat& mask,
                           cv::Point2d shift);

// x ↦ x + shift.
cv::Matx23d translation(cv::Point2d shift);

// The map `at` takes a pixel to.
cv::Point2d mapped(const cv::Matx23d& motion, cv::Point2d at);

// The object's motion from tiles of its texture, each found again by normalised correlation, and a
// similarity (shift, turn, scale) fitted to them with RANSAC; ice changes or hides the texture of
// the tiles it covers, and those fall out of the fit. The tiles are looked for around `start` (the
// global shift), around `fallback` (the confirmed shift) and in place; of those maps and the
// `fallback` shift, the one that moves the current texture inside `mask` back closest to the
// baseline's is the motion (the shift on a tie; alone, for an object too small for the tiles).
cv::Matx23d objectImageMotion(const cv::Mat& baselineLeft, const cv::Mat& currentLeft, const cv::Mat& mask,
                              cv::Point2d start, cv::Point2d fallback);

}  // namespace icewatch::volume
