// Scene directories on disk, and the debug pictures a person looks at (the seed paper's
// Figures 10-11: disparity, thickness, point cloud).
#include "core/volume/scene_files.hpp"

#include <cmath>
#include <fstream>

#include <opencv2/imgcodecs.hpp>

#include "core/common/error.hpp"
#include "core/volume/roi.hpp"

namespace icewatch::volume {

namespace {

std::string sizeText(cv::Size s) { return std::to_string(s.width) + "x" + std::to_string(s.height); }

cv::Mat readFrame(const std::filesystem::path& path) {
    if (!std::filesystem::is_regular_file(path)) {
        throw Error(kExitNoInput, path.string() + ": missing");
    }
    cv::Mat image;
    try {
        image = cv::imread(path.string(), cv::IMREAD_COLOR);
    } catch (const cv::Exception&) {
        image.release();
    }
    if (image.empty()) {
        throw Error(kExitDataErr, path.string() + ": not a readable image");
    }
    return image;
}

void writeImage(const std::filesystem::path& path, const cv::Mat& image) {
    bool ok = false;
    try {
        ok = !image.empty() && cv::imwrite(path.string(), image);
    } catch (const cv::Exception&) {
        ok = false;
    }
    if (!ok) throw Error(kExitCantCreate, path.string() + ": cannot write");
}

}  // namespace

SceneFiles loadSceneDirectory(const std::filesystem::path& dir, const RecordingReader& readRecording,
                              const CaptureAverageOptions& averaging) {
    if (!std::filesystem::is_directory(dir)) {
        throw Error(kExitNoInput, dir.string() + ": scene directory not found");
    }
    SceneFiles scene;
    scene.calibration = calib::loadCalibration(dir / "calibration.yaml");
    const cv::Size expected(2 * scene.calibration.imageSize.width, scene.calibration.imageSize.height);
    auto readCapture = [&](const std::string& name) {
        CaptureAccumulator accumulator(averaging);
        const FrameSink sink = [&](const cv::Mat& frame, const std::string& frameName) {
            if (frame.size() != expected) {
                throw Error(kExitDataErr, frameName + ": frame is " + sizeText(frame.size()) +
                                              ", but calibration.yaml describes eyes of " +
                                              sizeText(scene.calibration.imageSize) + " (a side-by-side frame of " +
                                              sizeText(expected) + ")");
            }
            try {
                accumulator.add(frame, frameName);
            } catch (const InvalidInput& e) {
                throw Error(kExitDataErr, e.what());
            }
        };
        const auto recording = dir / name;
        if (std::filesystem::is_directory(recording)) {
            if (!readRecording) throw Error(kExitUsage, recording.string() + ": recordings cannot be read here");
            readRecording(recording, sink);
            if (accumulator.framesAdded() == 0) throw Error(kExitDataErr, recording.string() + ": no frames");
        } else {
            const auto single = dir / (name + ".png");
            sink(readFrame(single), single.string());
        }
        AveragedCapture averaged = accumulator.finish();
        if (averaged.frame.empty()) throw Error(kExitDataErr, recording.string() + ": capture: " + averaged.reason);
        return averaged;
    };
    scene.before = readCapture("before");
    scene.after = readCapture("after");
    if (std::filesystem::exists(dir / "roi.json")) {
        scene.roi = loadRoiPolygon(dir / "roi.json");
    }
    return scene;
}

void writeDebugOutput(const VolumeResult& result, const std::filesystem::path& dir) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) throw Error(kExitCantCreate, dir.string() + ": cannot create (" + ec.message() + ")");
    writeImage(dir / "disparity.png", result.disparityColour);
    writeImage(dir / "thickness.png", result.thicknessColour);
    const auto plyPath = dir / "cloud.ply";
    std::ofstream ply(plyPath);
    ply << "ply\nformat ascii 1.0\ncomment current surface in the baseline camera frame, mm; colour = ice thickness\n"
        << "element vertex " << result.cloudMm.size() << "\nproperty float x\nproperty float y\nproperty float z\n"
        << "property float thickness_mm\nproperty uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n";
    const double scale = std::max(1.0, result.maxThicknessMm);
    for (std::size_t i = 0; i < result.cloudMm.size(); ++i) {
        const float t = std::isnan(result.cloudThicknessMm[i]) ? 0.0f : result.cloudThicknessMm[i];
        const int level = static_cast<int>(std::clamp(t / scale, 0.0, 1.0) * 255.0);
        ply << result.cloudMm[i][0] << ' ' << result.cloudMm[i][1] << ' ' << result.cloudMm[i][2] << ' ' << t << ' '
            << level << ' ' << level << ' ' << 255 - level << '\n';
    }
    if (!ply) throw Error(kExitCantCreate, plyPath.string() + ": cannot write");
}

}  // namespace icewatch::volume
