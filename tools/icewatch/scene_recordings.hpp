#pragma once

#include <filesystem>

#include "core/config/config.hpp"
#include "core/volume/scene_files.hpp"

namespace icewatch::cli {

// A scene's capture recording (recording.json and the frames as the camera sent them), decoded
// by the camera's own frame decoder and handed to `sink` one frame at a time. Throws Error naming
// the file: 66 when recording.json or a frame is missing, 65 when a frame does not decode or has
// another size than recorded.
void readCaptureRecording(const std::filesystem::path& dir, const volume::FrameSink& sink);

}  // namespace icewatch::cli
