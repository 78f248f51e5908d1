#pragma once

#include <filesystem>
#include <vector>

#include <opencv2/core.hpp>

#include "core/calib/stereo_calibration.hpp"

namespace icewatch::volume {

// Reads roi.json: {"polygon": [[x, y], ...]} in left-eye pixels of the camera frame. Throws
// Error(kExitDataErr / kExitNoInput) naming the file.
std::vector<cv::Point2d> loadRoiPolygon(const std::filesystem::path& path);

// x0, y0, x1, y1, ... (the configuration's form) to points; throws InvalidInput on an odd count or
// fewer than 3 points.
std::vector<cv::Point2d> polygonFromFlat(const std::vector<double>& flat);

// The polygon, given in raw left-eye pixels, as a mask in rectified left pixels.
cv::Mat roiMaskFromPolygon(const std::vector<cv::Point2d>& polygon, const calib::StereoCalibration& calibration);

// Without a polygon: the largest connected surface at the dominant depth of the capture
// (the blade fills most of a well-aimed view), holes filled; then, twice, the largest within the
// same band of the plane that part lies on, so that an object turned out of the view keeps the
// ends the band about one depth cuts off. Empty mask if nothing is found.
cv::Mat segmentRoi(const cv::Mat& points, double depthBandMm);

// Without a polygon, against a featureless background: the object is what that background, reached
// from the frame's edge as from outside an outline drawn around the whole view, leaves of the
// surface at the dominant depth (segmentRoi), its largest part with its holes filled, and its edge
// found again from an outline drawn a little wider around that part. The matcher
// fills a featureless sky with the depth of the object beside it, so depth alone finds the view;
// the sky's look does not follow it (objectInDrawnOutline). Where the frame's edge is not mostly
// featureless (a table, an object filling the view) it is segmentRoi's region. `grey`: the left
// eye (CV_32F, 0 where nothing was pictured); `minTextureGrey`, `minContrastGrey` as for a drawn
// outline.
cv::Mat segmentObject(const cv::Mat& points, const cv::Mat& grey, double depthBandMm, double minTextureGrey,
                      double minContrastGrey);

// The share of the frame's edge pixels that `mask` covers. An object in view reaches two sides of
// the frame at most (a blade across it); a segmented region that reaches most of the edge is the
// view itself: a featureless sky the matcher filled with the object's depth, or a table the
// object lies on, at its depth too.
double frameEdgeShare(const cv::Mat& mask);

}  // namespace icewatch::volume
