#pragma once

namespace icewatch::stereo {

// Every tunable of every matching method, with its documented default. Settable from the
// configuration file's "stereo" section.
struct Parameters {
    // --- OpenCV StereoSGBM baseline (3-way mode) ---
    int sgbmBlockSize = 5;        // matched block size, odd
    bool sgbmFillHoles = true;    // fill invalid pixels from the nearest valid neighbour on the row,
                                  // as the reference figures in shared/data/README.md were measured
};

}  // namespace icewatch::stereo
