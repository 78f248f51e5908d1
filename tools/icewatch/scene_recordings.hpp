#pragma once

#include <filesystem>

#include "core/config/config.hpp"
#include "core/volume/capture_average.hpp"
#include "core/volume/scene_files.hpp"

namespace icewatch::cli {

// A scene's capture recording (recording.json and the frames as the camera sent them), decoded
// by the camera's own frame decoder. Throws Error naming the file: 66 when recording.json or a
// frame is missing, 65 when a frame does not decode or has another size than recorded.
volume::CaptureFiles readCaptureRecording(const std::filesystem::path& dir);

// One capture of a scene as the chain measures it: the float average of its healthy, still
// frames. Throws Error(65) naming the frames when too few remain.
volume::AveragedCapture averageSceneCapture(const volume::CaptureFiles& capture, const config::ImageHealthConfig& health);

}  // namespace icewatch::cli
