#pragma once
// Planes and a camera the volume tests share, in camera coordinates (x right, y down, z ahead).

#include <opencv2/core.hpp>

#include "core/volume/height_grid.hpp"

namespace icewatch::volume::test {

// A 640x480 camera of 1000 px focal length, centred: a pixel is a millimetre at 1 m.
inline const cv::Matx33d kCamera(1000, 0, 320, 0, 1000, 240, 0, 0, 1);

// The ground 100 mm below the camera, its normal up towards the camera: image rows above the
// centre look over its horizon, row 240 along it.
inline PlaneFrame groundBelowCamera() {
    PlaneFrame ground;
    ground.origin = {0, 100, 1000};
    ground.normal = {0, -1, 0};
    ground.axisU = {1, 0, 0};
    ground.axisV = ground.normal.cross(ground.axisU);
    return ground;
}

}  // namespace icewatch::volume::test
