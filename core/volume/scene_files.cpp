// Scene directories on disk (the pictures a person looks at are core/pictures').
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
        if (averaged.frame.empty() && scene.unusable.empty()) {
            scene.unusable = recording.string() + ": capture: " + averaged.reason;
        }
        return averaged;
    };
    scene.before = readCapture("before");
    scene.after = readCapture("after");
    if (std::filesystem::exists(dir / "roi.json")) {
        scene.roi = loadRoiPolygon(dir / "roi.json");
    }
    return scene;
}

}  // namespace icewatch::volume
