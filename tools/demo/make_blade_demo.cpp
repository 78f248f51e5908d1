// make_blade_demo SCENE_DIR OUT_DIR: turns a scene rendered by `icewatch synth --scene blade
// --frames N` into what `tools/dev demo` plays through the fake camera: two MJPEG recordings as the
// HBVCAM would deliver them (baseline/ of the clean blade, recording/ of the iced one: each frame
// with its own sensor noise and JPEG encoding, without Huffman tables as UVC sends them), the
// scene's calibration and truth, and the daemon configurations that average them.
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <vector>

#include <nlohmann/json.hpp>

#include "drivers/v4l2/frame_decoder.hpp"
#include "drivers/v4l2/recording.hpp"

namespace {

namespace fs = std::filesystem;

constexpr int kFps = 30;

// The rendered capture's frames, as a camera recording.
int copyRecording(const fs::path& from, const fs::path& out) {
    const icewatch::v4l2::Recording rendered = icewatch::v4l2::readRecording(from);
    icewatch::v4l2::RecordingWriter writer(out, "synthetic: icewatch synth, tools/demo/make_blade_demo",
                                           icewatch::v4l2::PixelFormat::kMjpeg, rendered.width, rendered.height, kFps);
    for (std::size_t i = 0; i < rendered.frames.size(); ++i) {
        std::ifstream in(rendered.framePath(i), std::ios::binary);
        const std::vector<std::uint8_t> jpeg((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        const auto mjpeg = icewatch::v4l2::withoutHuffmanTables(jpeg.data(), jpeg.size());
        writer.add(mjpeg.data(), mjpeg.size(), static_cast<std::int64_t>(i) * 1000000 / kFps);
    }
    writer.finish();
    return static_cast<int>(rendered.frames.size());
}

// The daemon configuration for the demo, relative to the repository root (tools/dev runs there).
void writeConfig(const fs::path& file, const std::string& device, const std::vector<double>& roi, int frames) {
    const nlohmann::json config = {
        {"camera", {{"device", device}, {"width", 2560}, {"height", 720}}},
        // Paths relative to the configuration file: the demo runs from any directory.
        {"calibration", {{"file", "calibration.yaml"}}},
        // Every recorded frame in one averaged capture; a few may be dropped.
        {"daemon", {{"burst_frames", frames}, {"baseline_frames", frames}, {"min_frames", (frames + 1) / 2}}},
        {"gpio", {{"chip", "fake"}}},
        {"volume", {{"roi_polygon", roi}}},
    };
    std::ofstream(file) << config.dump(2) << "\n";
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 3) {
        std::cerr << "usage: make_blade_demo SCENE_DIR OUT_DIR   (SCENE_DIR from icewatch synth --scene blade --frames N)\n";
        return 64;
    }
    const fs::path scene = argv[1];
    const fs::path out = argv[2];
    try {
        fs::create_directories(out);
        const int frames = copyRecording(scene / "before", out / "baseline");
        copyRecording(scene / "after", out / "recording");
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
        // A frame is made only when the daemon asks for one: each burst averages the recording's
        // frames once each, in order. At the camera's 30 fps the daemon took the freshest frames,
        // which frames depended on the machine's pace, and runs read -2.3 to +8.4 %.
        writeConfig(out / "icewatch-baseline.json", "fake:baseline?pace=fast", roi, frames);
        writeConfig(out / "icewatch.json", "fake:recording?pace=fast", roi, frames);
    } catch (const std::exception& e) {
        std::cerr << "make_blade_demo: " << e.what() << "\n";
        return 73;
    }
    return 0;
}
