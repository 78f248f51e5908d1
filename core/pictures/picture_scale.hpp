#pragma once

namespace icewatch::pictures {

// The configuration's "pictures" section (config/icewatch.json documents it).
struct PictureScale {
    // Thickness pictures run from 0 to this, every day the same, so that two days compare.
    double maxThicknessMm = 10.0;
};

}  // namespace icewatch::pictures
