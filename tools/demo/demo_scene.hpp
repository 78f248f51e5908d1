#pragma once

#include <cstdint>

#include <opencv2/core.hpp>

// The demo recording's scene: a textured plane seen by both eyes with a known, constant
// disparity. The texture is a pure function of integer coordinates (hashed value noise at three
// scales), so the generator and the tests that check the recording render the same pixels on any
// machine.
namespace icewatch::demo {

inline constexpr int kFrameWidth = 2560;  // side by side, as the HBVCAM's 2560x720 mode
inline constexpr int kFrameHeight = 720;
inline constexpr int kFps = 30;
inline constexpr int kFrames = 6;
inline constexpr int kDisparityPx = 24;  // right eye = left eye shifted left by this
inline constexpr int kPanPxPerFrame = 7; // the scene drifts so frames differ
inline constexpr int kJpegQuality = 85;

inline std::uint32_t hash(std::int32_t x, std::int32_t y, std::uint32_t seed) {
    std::uint32_t h = static_cast<std::uint32_t>(x) * 0x8da6b343u ^ static_cast<std::uint32_t>(y) * 0xd8163841u ^
                      seed * 0xcb1ab31fu;
    h ^= h >> 13;
    h *= 0x5bd1e995u;
    h ^= h >> 15;
    return h;
}

// Bilinear value noise with cells of `cell` pixels, in [0, 255].
inline int valueNoise(std::int32_t x, std::int32_t y, std::int32_t cell, std::uint32_t seed) {
    const std::int32_t cx = x >= 0 ? x / cell : (x - cell + 1) / cell;
    const std::int32_t cy = y / cell;
    const std::int32_t fx = x - cx * cell;
    const std::int32_t fy = y - cy * cell;
    auto v = [&](std::int32_t i, std::int32_t j) { return static_cast<std::int32_t>(hash(cx + i, cy + j, seed) & 255); };
    const std::int32_t top = v(0, 0) * (cell - fx) + v(1, 0) * fx;
    const std::int32_t bottom = v(0, 1) * (cell - fx) + v(1, 1) * fx;
    return (top * (cell - fy) + bottom * fy) / (cell * cell);
}

// The plane's colour at texture coordinate (u, v).
inline cv::Vec3b texture(std::int32_t u, std::int32_t v) {
    cv::Vec3b bgr;
    for (int c = 0; c < 3; ++c) {
        const auto seed = static_cast<std::uint32_t>(c + 1);
        const int value = (valueNoise(u, v, 96, seed) * 2 + valueNoise(u, v, 24, seed + 7) * 2 +
                           valueNoise(u, v, 6, seed + 13)) / 5;
        bgr[c] = static_cast<std::uint8_t>(value);
    }
    return bgr;
}

// One eye of frame `frame` (0-based): the left eye sees texture column x + pan, the right eye
// x + pan + disparity.
inline cv::Mat renderEye(int frame, bool rightEye, int eyeWidth = kFrameWidth / 2, int height = kFrameHeight) {
    cv::Mat eye(height, eyeWidth, CV_8UC3);
    const int shift = frame * kPanPxPerFrame + (rightEye ? kDisparityPx : 0);
    for (int y = 0; y < height; ++y) {
        auto* row = eye.ptr<cv::Vec3b>(y);
        for (int x = 0; x < eyeWidth; ++x) {
            row[x] = texture(x + shift, y);
        }
    }
    return eye;
}

}  // namespace icewatch::demo
