#pragma once

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "core/volume/height_grid.hpp"
#include "core/volume/registration.hpp"

namespace icewatch::volume {

struct TextureRegistrationOptions {
    int maxFeatures = 3000;           // corners tracked from the current left image
    double minFeatureDistancePx = 4;  // between two corners
    int trackWindowPx = 21;           // Lucas-Kanade window
    double maxRoundTripPx = 0.5;      // forward-backward tracking error accepted
    int depthRadiusPx = 6;            // depths averaged over (2r+1)² pixels before lifting a match
    double inlierMm = 2.0;            // RANSAC: a match this close to the model in the plane is an inlier
    int ransacIterations = 400;
    std::uint32_t seed = 1;           // RANSAC draws (fixed: the result does not depend on timing)
};

struct TextureRegistrationResult {
    bool ok = false;       // enough inliers for a rigid fit
    RigidTransform transform;  // current -> baseline
    int tracked = 0;       // features tracked both ways and lifted to 3-D on both surfaces
    int inliers = 0;
    double rmsMm = 0;      // of the inliers' in-plane distances after the final fit
    std::vector<cv::Point2f> inlierPixels;  // where the inliers are in the current left image: unchanged texture
};

// Rigid current -> baseline transform from the image texture: corners of the current left image
// inside `mask` are tracked into the baseline left image (pyramidal Lucas-Kanade, checked back),
// lifted to 3-D with both organised clouds (CV_32FC3, NaN = none), put in the object's `plane`
// and fitted robustly there (RANSAC on two matches, Umeyama without scale, refit on the inliers):
// a turn about the plane's normal and an in-plane translation, no out-of-plane motion. It pins
// what geometry cannot: a
// nearly extruded blade sliding along its span or turning about its normal. Ice changes the
// texture and the depth where it lies, so its matches fail the round trip or the inlier test.
TextureRegistrationResult registerByTexture(const cv::Mat& baselineLeft, const cv::Mat& baselinePoints,
                                            const cv::Mat& currentLeft, const cv::Mat& currentPoints,
                                            const cv::Mat& mask, const PlaneFrame& plane,
                                            const TextureRegistrationOptions& options = {});

// The rigid transform that maps `from` onto `to` in the least-squares sense (Umeyama, no scale).
// Needs at least 3 non-collinear pairs; throws InvalidInput otherwise.
RigidTransform fitRigid(const std::vector<cv::Vec3d>& from, const std::vector<cv::Vec3d>& to);

}  // namespace icewatch::volume
