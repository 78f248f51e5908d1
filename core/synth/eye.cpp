// The camera stage of the synthetic scenes: each eye is z-buffer rasterised at supersampling²
// samples per pixel, shaded, and box-filtered down to its pixels, as a sensor integrates the light
// over each pixel. The left eye also yields the truth maps of the geometry it sees.
#include "core/synth/eye.hpp"

#include <algorithm>

#include <opencv2/imgproc.hpp>

#include "core/stereo/matcher.hpp"
#include "core/synth/highlight.hpp"
#include "core/synth/refraction.hpp"

namespace icewatch::synth {

namespace {

// Averages over each pixel's samples; stereo::kInvalidDisparity where any sample sees the sky (a
// pixel astride an outline against the sky has no single depth).
EyeTruth truthFromSamples(const SampleBuffer& samples, int supersampling, cv::Size eye, double focalPx,
                          double baselineMm) {
    EyeTruth truth{cv::Mat(eye, CV_32F), cv::Mat(eye, CV_32F)};
    const int s = supersampling;
    for (int y = 0; y < eye.height; ++y)
        for (int x = 0; x < eye.width; ++x) {
            double inverseDepth = 0, ice = 0;
            bool whole = true;
            for (int j = 0; j < s && whole; ++j)
                for (int i = 0; i < s; ++i) {
                    const int sy = y * s + j, sx = x * s + i;
                    if (samples.material.at<int>(sy, sx) < 0) {
                        whole = false;
                        break;
                    }
                    inverseDepth += samples.inverseDepth.at<float>(sy, sx);
                    ice += samples.attributes.at<VertexAttributes>(sy, sx)[kAttributeExtra];
                }
            const float none = stereo::kInvalidDisparity;
            truth.disparity.at<float>(y, x) = whole ? static_cast<float>(focalPx * baselineMm * inverseDepth / (s * s)) : none;
            truth.iceMm.at<float>(y, x) = whole ? static_cast<float>(ice / (s * s)) : none;
        }
    return truth;
}

}  // namespace

cv::Mat renderEye(const std::vector<Mesh>& meshes, const Shading& shading, const calib::StereoCalibration& calibration,
                  double centreXMm, int supersampling, double truthBaselineMm, EyeTruth* truth) {
    const cv::Size eye = calibration.imageSize;
    PinholeView view;
    view.fPx = calibration.M1.at<double>(0, 0) * supersampling;
    view.cxPx = (calibration.M1.at<double>(0, 2) + 0.5) * supersampling - 0.5;
    view.cyPx = (calibration.M1.at<double>(1, 2) + 0.5) * supersampling - 0.5;
    view.centreXMm = centreXMm;
    view.size = {eye.width * supersampling, eye.height * supersampling};
    // Each eye sees what lies under clear ice along its own rays, and highlights where its own
    // view mirrors the light (copies only when there is any of either).
    const bool anyLayer =
        std::any_of(meshes.begin(), meshes.end(), [](const Mesh& m) { return m.clearLayer.has_value(); });
    const bool glossy = shading.look.gloss > 0;
    std::vector<Mesh> seen;
    if (anyLayer || glossy) {
        seen.reserve(meshes.size());
        for (const Mesh& mesh : meshes) {
            seen.push_back(seenThroughClearLayer(mesh, centreXMm));
            if (glossy) addHighlights(seen.back(), centreXMm, shading.ice, shading.look.gloss);
        }
    }
    const SampleBuffer samples = rasterize(anyLayer || glossy ? seen : meshes, view);
    cv::Mat fine(view.size, CV_32F);
    // Rows in fixed stripes: each sample is a pure function of its inputs, so the result does not
    // depend on the thread count.
    cv::parallel_for_(cv::Range(0, view.size.height), [&](const cv::Range& rows) {
        for (int y = rows.start; y < rows.end; ++y) {
            const auto* material = samples.material.ptr<int>(y);
            const auto* attributes = samples.attributes.ptr<VertexAttributes>(y);
            auto* out = fine.ptr<float>(y);
            const auto* inverseDepth = samples.inverseDepth.ptr<float>(y);
            const float skyY = 1.0f - static_cast<float>(y) / view.size.height;
            for (int x = 0; x < view.size.width; ++x) {
                const float skyX = static_cast<float>(x) / view.size.width;
                VertexAttributes a = attributes[x];
                if (shading.shadows && material[x] >= 0) {
                    // The sample's point on the surface, back through this eye's pinhole.
                    const double z = 1.0 / inverseDepth[x];
                    const cv::Vec3d p((x - view.cxPx) * z / view.fPx + view.centreXMm, (y - view.cyPx) * z / view.fPx, z);
                    if (shading.shadows->lit(p) < 1.0f) {
                        // In shadow only the ambient share of the light arrives, and nothing is mirrored.
                        const auto ambient = static_cast<float>(shading.look.ambient);
                        a[kAttributeShade] = std::min(a[kAttributeShade], ambient);
                        a[kAttributeHighlight] = 0.0f;
                    }
                }
                out[x] = shadeSample(shading, material[x], a, skyX, skyY);
            }
        }
    });
    cv::Mat pixels;
    cv::resize(fine, pixels, eye, 0, 0, cv::INTER_AREA);
    if (truth) *truth = truthFromSamples(samples, supersampling, eye, calibration.M1.at<double>(0, 0), truthBaselineMm);
    return pixels;
}

}  // namespace icewatch::synth
