#pragma once

#include <opencv2/core.hpp>

namespace icewatch::volume {

// The object inside an outline drawn over a textured background (a table, a rig), where the
// object stands above that background.
struct RaisedObject {
    cv::Mat object;                // CV_8U, 255 on the object: the outline less the background's margin in it
    double backgroundPercent = 0;  // of the outline, the margin found to be background and left out
    double stepMm = 0;             // how far the object stands above the background where they meet (0: not found)
};

struct RaisedObjectOptions {
    int ringPx = 12;             // the ring outside the outline that shows the background's plane
    int minRingPoints = 200;     // measured points of that ring a plane is fitted to
    double minRingMeasured = 0.5;  // share of the ring measured: a textured background, not the sky
    double toleranceSigmas = 4;  // a pixel within this many of the ring's σ from its plane is background...
    double minToleranceMm = 1.5; // ...and at least within this
    // The object must stand this far above the background where they meet (the median of its
    // pixels there)... Rendered, a blade lying on its table rose 4.7-5.1 mm there (its rim within
    // 3 mm of the table, the flood ran 20-25 px into it), one 8 mm above it 10.6-11.0 mm.
    double minStepMm = 6;
    double stepTolerances = 2.5;  // ...and this many tolerances (a blade lying flat: 1.7)
    int stepFromPx = 4;          // where they meet: the object's pixels this far from the margin...
    int stepToPx = 12;           // ...up to this far (past the matcher's smeared depth edge)
    double minMarginShare = 0.01;  // less margin than this share of the outline is the drawn edge's fringe
};

// An outline drawn loosely over a textured background holds a margin of that background: the
// matcher and the trackers measure it, and the chain took it for the object's clean surface. Where
// the object lies flat on it that is harmless (the margin is continuous with the object, and ice
// that stands out of the object over it stands on it); where the object stands above it, the
// margin is a surface that the object's ice hides from the view, and ice over it reads as the whole
// height between the ice and the background (a bead over a glaze on a blade 19 mm above its table,
// drawn 20 px wide: +104 % as ok outside its uncertainty), and the image's texture gate judges the
// background's texture for the object's (a faint blade passed on the table's).
//
// So the margin is taken out when the object stands clearly above it: the background's plane is
// fitted to the measured ring outside the outline; the outline's pixels within the tolerance of it
// that the ring reaches through such pixels are the margin; and it is left out only when the
// object's pixels where they meet it stand at least the step above the plane at their median. An
// object that rises from its background gradually (a blade lying on its table, whose rim is within
// millimetres of it) comes back as drawn, and so does an outline over the sky (its ring unmeasured)
// or drawn on the object's edge (no margin).
//
// outline: CV_8U; points: CV_32FC3, the baseline's points in camera millimetres, NaN where unmeasured.
RaisedObject objectAboveItsBackground(const cv::Mat& outline, const cv::Mat& points,
                                      const RaisedObjectOptions& options = {});

}  // namespace icewatch::volume
