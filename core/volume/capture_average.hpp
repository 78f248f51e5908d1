#pragma once

#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/config/config.hpp"

namespace icewatch::volume {

struct CaptureAverageOptions {
    config::ImageHealthConfig health;  // each frame's image-health check
    double maxFrameShiftPx = 0.25;     // a frame shifted more than this against the others moved (gust, knock)
    double maxChangedPercent = 0.5;    // a frame whose pixels differ from the others' beyond noise over more
                                       // than this share of the image saw something pass (a bird)
    int minFrames = 1;                 // fewer healthy, still frames: no capture
};

// A frame left out of the average, and why: flag is dark, saturated, blurred, low_contrast (the
// image-health check), moved or disturbed.
struct DroppedFrame {
    std::string flag;
    std::string reason;  // "frame 3: left eye: ..."
};

// One capture: the float average of the frames that showed the same still scene.
struct AveragedCapture {
    cv::Mat frame;                     // CV_32FC1 grey side-by-side frame, 0..255, never rounded;
                                       // empty when fewer than minFrames were usable
    // One draw of the average's own noise (CV_32FC1, the frame's layout): the same frames combined
    // so that the scene cancels and the noise keeps the average's variance and spectrum. What the
    // image shows of it cannot be told from texture, so what reads texture takes it off. Empty
    // with fewer than two frames.
    cv::Mat noise;
    int framesUsed = 0;
    int framesHealthy = 0;             // passed the image-health check
    std::vector<DroppedFrame> dropped;
    std::string reason;                // why there is no frame
};

// A parked blade and a fixed camera give many frames of one scene in a fraction of a second; their
// average divides the sensor noise, and most of the JPEG and quantisation error, by √N. Frames that
// fail the health check are left out, then those that disagree with the scene most frames show: a
// frame whose global shift against it exceeds maxFrameShiftPx moved, one with more than
// maxChangedPercent of its pixels beyond 6 robust σ of the difference saw something pass.
//
// Frames are taken one at a time and summed as they come, so memory does not grow with the burst:
// the first healthy frame is the reference, and the first frame that disagrees with it opens a
// second group with its own reference and sum. The larger group is the capture (the first on a
// tie), so a disturbed or moved first frame loses to the frames after it instead of casting them
// all out; a frame that fits neither group is left out. Two sums and two alternating sums (for
// the noise), two half-size references and the frame in hand are all that is held, whatever the
// burst's length.
//
// Frames: CV_8UC3 (BGR) or CV_8UC1, all of one size; a name (may be empty) names a frame in the
// reasons. add() throws InvalidInput when a frame is empty, not 8-bit or of another size (naming it).
class CaptureAccumulator {
public:
    explicit CaptureAccumulator(const CaptureAverageOptions& options = {});
    ~CaptureAccumulator();
    CaptureAccumulator(CaptureAccumulator&&) noexcept;
    CaptureAccumulator& operator=(CaptureAccumulator&&) noexcept;

    void add(const cv::Mat& frame, const std::string& name = {});
    int framesAdded() const;
    // The average of the frames added so far (the accumulator is then empty again).
    AveragedCapture finish();

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// All frames at once, through a CaptureAccumulator. Throws InvalidInput when there are none.
AveragedCapture averageCapture(const std::vector<cv::Mat>& frames, const std::vector<std::string>& names,
                               const CaptureAverageOptions& options = {});

}  // namespace icewatch::volume
