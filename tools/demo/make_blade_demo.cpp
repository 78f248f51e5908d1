// make_blade_demo SCENE_DIR OUT_DIR: turns a scene rendered by `icewatch synth --scene blade` into
// what `tools/dev demo` plays through the fake camera: two MJPEG recordings as the HBVCAM would
// deliver them (baseline/ of the clean blade, recording/ of the iced one), the scene's
// calibration and truth, and the daemon configurations that use them.
//
// Each recorded frame is the rendered frame with its own sensor noise, so a burst is a burst of
// different exposures of the same scene, as on the tower, and not one picture repeated.
#include <filesystem>
#include <fstream>
#include <iostream>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "drivers/v4l2/frame_decoder.hpp"
#include "drivers/v4l2/recording.hpp"

namespace {

namespace fs = std::filesystem;

constexpr int kFrames = 3;            // a burst of three: the demo config's daemon.burst_frames
constexpr int kFps = 30;
constexpr int kJpegQuality = 92;
constexpr double kNoiseSigma = 1.0;   // grey levels, on top of the render's own noise

void writeRecording(const fs::path& frameFile, const fs::path& out, int seed) {
    const cv::Mat frame = cv::imread(frameFile.string(), cv::IMREAD_COLOR);
    if (frame.empty()) {
        throw std::runtime_error(frameFile.string() + ": cannot read the rendered frame");
    }
    icewatch::v4l2::RecordingWriter writer(out, "synthetic: icewatch synth, tools/demo/make_blade_demo",
                                           icewatch::v4l2::PixelFormat::kMjpeg, frame.cols, frame.rows, kFps);
    cv::RNG random(static_cast<std::uint64_t>(seed));
    for (int i = 0; i < kFrames; ++i) {
        cv::Mat noise(frame.size(), CV_32FC3);
        random.fill(noise, cv::RNG::NORMAL, 0.0, kNoiseSigma);
        cv::Mat noisy;
        frame.convertTo(noisy, CV_32FC3);
        noisy += noise;
        noisy.convertTo(noisy, CV_8UC3);
        std::vector<std::uint8_t> jpeg;
        cv::imencode(".jpg", noisy, jpeg, {cv::IMWRITE_JPEG_QUALITY, kJpegQuality});
        // UVC cameras send MJPEG without Huffman tables; so does the demo.
        const auto mjpeg = icewatch::v4l2::withoutHuffmanTables(jpeg.data(), jpeg.size());
        writer.add(mjpeg.data(), mjpeg.size(), std::int64_t{i} * 1000000 / kFps);
    }
    writer.finish();
}

// The daemon configuration for the demo, relative to the repository root (tools/dev runs there).
void writeConfig(const fs::path& file, const std::string& device, const std::vector<double>& roi) {
    const nlohmann::json config = {
        {"camera", {{"device", device}, {"width", 2560}, {"height", 720}}},
        {"calibration", {{"file", "tools/demo/blade/calibration.yaml"}}},
        // The blade is weakly textured: its Laplacian variance is ~12 where a textured scene gives
        // hundreds, so the sharpness floor is set for this scene (a sigma-4 blur of it gives ~3).
        {"daemon", {{"burst_frames", kFrames}, {"min_frames", 2}, {"health", {{"min_sharpness", 5.0}}}}},
        {"gpio", {{"chip", "fake"}}},
        {"volume", {{"roi_polygon", roi}}},
    };
    std::ofstream(file) << config.dump(2) << "\n";
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 3) {
        std::cerr << "usage: make_blade_demo SCENE_DIR OUT_DIR   (SCENE_DIR from icewatch synth --scene blade)\n";
        return 64;
    }
    const fs::path scene = argv[1];
    const fs::path out = argv[2];
    try {
        fs::create_directories(out);
        writeRecording(scene / "before.png", out / "baseline", 1);
        writeRecording(scene / "after.png", out / "recording", 2);
        fs::copy_file(scene / "calibration.yaml", out / "calibration.yaml", fs::copy_options::overwrite_existing);
        fs::copy_file(scene / "truth.json", out / "truth.json", fs::copy_options::overwrite_existing);
        fs::copy_file(scene / "roi.json", out / "roi.json", fs::copy_options::overwrite_existing);
        std::ifstream roiFile(scene / "roi.json");
        const nlohmann::json roiJson = nlohmann::json::parse(roiFile);
        std::vector<double> roi;
        for (const auto& point : roiJson.at("polygon")) {
            roi.push_back(point.at(0).get<double>());
            roi.push_back(point.at(1).get<double>());
        }
        writeConfig(out / "icewatch-baseline.json", "fake:tools/demo/blade/baseline", roi);
        writeConfig(out / "icewatch.json", "fake:tools/demo/blade/recording", roi);
    } catch (const std::exception& e) {
        std::cerr << "make_blade_demo: " << e.what() << "\n";
        return 73;
    }
    return 0;
}
