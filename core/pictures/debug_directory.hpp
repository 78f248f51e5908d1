#pragma once

#include <filesystem>

#include <opencv2/core.hpp>

#include "core/pictures/measurement_pictures.hpp"
#include "core/volume/chain.hpp"

namespace icewatch::pictures {

// One picture as PNG (or what the extension says). Throws Error(kExitCantCreate) naming the file.
void writePicture(const std::filesystem::path& path, const cv::Mat& picture);

// What a measurement has, for a person: left.png, disparity.png and thickness.png (a refused
// measurement's carry its reason), and cloud.ply when a volume was measured (the current surface
// in the baseline's frame, coloured by thickness on the pictures' scale). Creates the directory.
// Throws Error(kExitCantCreate).
void writeDebugDirectory(const MeasurementPictures& pictures, const volume::VolumeResult& result,
                         const PictureScale& scale, const std::filesystem::path& dir);

}  // namespace icewatch::pictures
