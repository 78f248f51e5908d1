#pragma once

#include <filesystem>

#include <opencv2/core.hpp>

#include "core/pictures/measurement_pictures.hpp"
#include "core/volume/chain.hpp"

namespace icewatch::pictures {

// One picture as PNG (or what the extension says). Throws Error(kExitCantCreate) naming the file.
void writePicture(const std::filesystem::path& path, const cv::Mat& picture);

// What a measurement has, for a person: left.png, disparity.png and thickness.png (a refused
// measurement's carry its reason), and when a volume was measured cloud.ply (the current surface
// in the baseline's frame, coloured by thickness on the pictures' scale) and thickness_mm.pfm (the
// thickness where it lies in the current left eye, mm, NaN where none). Creates the directory.
// Throws Error(kExitCantCreate).
void writeDebugDirectory(const MeasurementPictures& pictures, const volume::VolumeResult& result,
                         const PictureScale& scale, const std::filesystem::path& dir);

}  // namespace icewatch::pictures
