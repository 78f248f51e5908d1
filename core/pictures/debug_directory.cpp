// A measurement's pictures and point cloud on disk (`icewatch volume --debug-dir`), as the seed
// paper's Figures 10-11 show them: disparity, thickness, point cloud.
#include "core/pictures/debug_directory.hpp"

#include <cmath>
#include <fstream>

#include <opencv2/imgcodecs.hpp>

#include "core/common/error.hpp"
#include "core/pictures/colour_scale.hpp"

namespace icewatch::pictures {

void writePicture(const std::filesystem::path& path, const cv::Mat& picture) {
    bool ok = false;
    try {
        ok = !picture.empty() && cv::imwrite(path.string(), picture);
    } catch (const cv::Exception&) {
        ok = false;
    }
    if (!ok) throw Error(kExitCantCreate, path.string() + ": cannot write the picture");
}

namespace {

void writeCloud(const volume::VolumeResult& result, const PictureScale& scale, const std::filesystem::path& path) {
    std::ofstream ply(path);
    ply << "ply\nformat ascii 1.0\ncomment current surface in the baseline camera frame, mm; colour = ice thickness, 0 .. "
        << scale.maxThicknessMm << " mm\n"
        << "element vertex " << result.cloudMm.size() << "\nproperty float x\nproperty float y\nproperty float z\n"
        << "property float thickness_mm\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n";
    const ColourScale colours{0.0, scale.maxThicknessMm, "mm", "thickness"};
    for (std::size_t i = 0; i < result.cloudMm.size(); ++i) {
        const float t = std::isnan(result.cloudThicknessMm[i]) ? 0.0f : result.cloudThicknessMm[i];
        const cv::Vec3b bgr = colourOf(t, colours);
        ply << result.cloudMm[i][0] << ' ' << result.cloudMm[i][1] << ' ' << result.cloudMm[i][2] << ' ' << t << ' '
            << int(bgr[2]) << ' ' << int(bgr[1]) << ' ' << int(bgr[0]) << '\n';
    }
    if (!ply) throw Error(kExitCantCreate, path.string() + ": cannot write");
}

}  // namespace

void writeDebugDirectory(const MeasurementPictures& pictures, const volume::VolumeResult& result,
                         const PictureScale& scale, const std::filesystem::path& dir) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) throw Error(kExitCantCreate, dir.string() + ": cannot create (" + ec.message() + ")");
    if (!pictures.left.empty()) writePicture(dir / "left.png", pictures.left);
    if (!pictures.disparity.empty()) writePicture(dir / "disparity.png", pictures.disparity);
    if (!pictures.thickness.empty()) writePicture(dir / "thickness.png", pictures.thickness);
    if (result.ok) writeCloud(result, scale, dir / "cloud.ply");
    // The thickness the picture shows, as numbers (a float PFM, NaN where none, signed): to hold
    // against a rendered scene's truth_ice_mm.pfm, pixel by pixel.
    if (result.ok && !result.thicknessImageMm.empty()) writePicture(dir / "thickness_mm.pfm", result.thicknessImageMm);
}

}  // namespace icewatch::pictures
