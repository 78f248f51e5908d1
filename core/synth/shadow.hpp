#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "core/synth/rasterizer.hpp"

namespace icewatch::synth {

// Cast shadows of a directional light (the sun). A renderer that traces rays towards the light
// darkens what another surface hides from it: the table beside a blade lying on it, the plate
// beside a block, the blade behind its own horn. The shadow is fixed to the light, not to the
// surface it falls on: when the object moves, grows ice or the sun turns, the shadow's edge slides
// over texture that did not move, and a shadowed surface keeps only the ambient share of its light.
//
// The map is an orthographic depth buffer looking along the light: per cell the distance, along
// the light's direction, of the first caster surface the light meets.
class ShadowMap {
public:
    // casters: the meshes that can hide the light (camera frame, mm); towardsLight: unit vector
    // from the surfaces to the light; cellMm: the map's cell size (the shadow edges' resolution).
    ShadowMap(const std::vector<Mesh>& casters, const cv::Vec3d& towardsLight, double cellMm = 0.25);

    // 1 where the light reaches p (camera frame, mm), 0 where a caster lies between p and the
    // light. Surfaces of the casters themselves are lit where they are the first the light meets.
    float lit(const cv::Vec3d& p) const;

private:
    cv::Vec3d u_, v_, w_;  // the map's axes; w_ along the light's travel
    cv::Point2d origin_;   // (u, v) of cell (0, 0)'s centre
    double cellMm_ = 0.25;
    cv::Mat depth_;        // CV_32F, w of the first caster the light meets; +inf where none
};

}  // namespace icewatch::synth
