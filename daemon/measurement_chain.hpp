#pragma once

#include <functional>
#include <map>
#include <string>

#include <opencv2/core.hpp>

#include "core/common/side_by_side.hpp"

namespace icewatch::daemon {

// Pictures of one measurement for a person (GET /v1/images/latest/...): 8-bit BGR or grey.
struct ChainPictures {
    cv::Mat left;       // the rectified left eye, the region outlined (core/pictures)
    cv::Mat disparity;  // false-colour disparity with its colour bar
    cv::Mat thickness;  // ice thickness over the left eye with its colour bar; a refusal's reason on each
};

struct ChainResult {
    enum class Status {
        Ok,       // a volume with its uncertainty
        Refused,  // the quality gate said no (too few disparities, no texture, ...): not a fault
        Failed,   // the chain could not run (bad calibration, an internal error): a fault
    };
    Status status = Status::Failed;
    std::string reason;  // why, when not Ok
    double volumeMm3 = 0.0;
    double uncertaintyMm3 = 0.0;  // expanded: coverageFactor standard deviations
    double coverageFactor = 1.0;
    double meanThicknessMm = 0.0;
    double meanThicknessUncertaintyMm = 0.0;  // expanded, as uncertaintyMm3
    double maxThicknessMm = 0.0;
    double iceAreaMm2 = 0.0;        // where thickness was integrated (possible ice, grown by the matcher's reach)
    double beyondOutlineMm3 = 0.0;  // of the volume, ice standing out of the clean blade's outline
    double validPercent = 0.0;    // share of the region with a valid disparity
    std::map<std::string, double> timingsMs;  // per stage
    ChainPictures pictures;
};

// The volume chain as the daemon needs it: rectify, match, reproject, register against the
// baseline, filter, grid, integrate, gate. Called from the service loop only.
class MeasurementChain {
public:
    virtual ~MeasurementChain() = default;

    // SHA-256 of the calibration it measures with; a baseline taken under another one is not used.
    virtual std::string calibrationSha256() const = 0;
    // Builds the reference (clean blade) surface from a pair. Not Ok: no baseline is set.
    // By value, as estimate. `noise`: one draw of the pair's own noise when it is an average
    // (volume::AveragedCapture::noise split as the pair; empty pairs when there is none).
    virtual ChainResult setBaseline(StereoPair clean, StereoPair noise) = 0;
    virtual bool hasBaseline() const = 0;
    // Measures one pair against the baseline. Bad images are a Refused result, never an exception.
    // By value: a caller that moves the pair in lets the chain free it once it is rectified.
    virtual ChainResult estimate(StereoPair current, StereoPair noise) = 0;
    // Called between the stages of setBaseline and estimate, on the caller's thread, when the
    // chain has stages: the service loop's watchdog learns that a long chain is still working.
    virtual void onProgress(std::function<void()> progress) { (void)progress; }
};

}  // namespace icewatch::daemon
