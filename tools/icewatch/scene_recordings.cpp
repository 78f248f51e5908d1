#include "tools/icewatch/scene_recordings.hpp"

#include <fstream>
#include <iterator>
#include <vector>

#include "core/common/error.hpp"
#include "drivers/v4l2/frame_decoder.hpp"
#include "drivers/v4l2/recording.hpp"

namespace icewatch::cli {

void readCaptureRecording(const std::filesystem::path& dir, const volume::FrameSink& sink) {
    const v4l2::Recording recording = v4l2::readRecording(dir);
    v4l2::FrameDecoder decoder;
    for (std::size_t i = 0; i < recording.frames.size(); ++i) {
        const auto path = recording.framePath(i);
        std::ifstream in(path, std::ios::binary);
        const std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        if (!in.good() && !in.eof()) throw Error(kExitNoInput, path.string() + ": cannot read");
        cv::Mat bgr;
        if (const auto problem = decoder.decode(recording.format, bytes.data(), bytes.size(), recording.width,
                                                recording.height, bgr)) {
            throw Error(kExitDataErr, path.string() + ": frame " + std::to_string(i + 1) + " does not decode (" +
                                          v4l2::dropReasonName(*problem) +
                                          (decoder.message().empty() ? "" : ": " + decoder.message()) + ")");
        }
        sink(bgr, path.string());
    }
}

}  // namespace icewatch::cli
