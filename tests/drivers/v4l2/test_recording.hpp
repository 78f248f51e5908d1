#pragma once

#include <filesystem>
#include <vector>

#include "core/common/side_by_side.hpp"
#include "drivers/v4l2/recording.hpp"

namespace icewatch::test {

// A small side-by-side recording written into dir: `frames` MJPEG frames of the demo scene at
// 2*eyeWidth x height, each frame different (the scene drifts), with its standard Huffman tables.
v4l2::Recording makeMjpegRecording(const std::filesystem::path& dir, int frames = 8, int eyeWidth = 640,
                                   int height = 480);
// The same as raw YUYV frames.
v4l2::Recording makeYuyvRecording(const std::filesystem::path& dir, int frames = 4, int eyeWidth = 640,
                                  int height = 480);

// Each frame of a recording decoded independently of the driver (cv::imdecode or cv::cvtColor)
// and split: what the capture must hand out.
std::vector<StereoPair> decodeRecording(const v4l2::Recording& recording);

// The index of the source pair that equals pair pixel for pixel, or -1.
int matchingSource(const StereoPair& pair, const std::vector<StereoPair>& sources);

}  // namespace icewatch::test
