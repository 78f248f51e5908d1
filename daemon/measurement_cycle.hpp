#pragma once

#include <functional>
#include <optional>

#include "core/config/config.hpp"
#include "daemon/cycle_result.hpp"
#include "daemon/frame_source.hpp"
#include "daemon/measurement_chain.hpp"

namespace icewatch::daemon {

// What one cycle produced before the alarm is applied: the result (alarm field not yet set) and
// the pictures of the measured capture, empty unless the chain measured it (a volume or a refusal).
struct CycleOutcome {
    CycleResult result;
    ChainPictures pictures;
};

// Asked between frames; true abandons the cycle (SIGTERM).
using CancelCheck = std::function<bool()>;
// Called after every frame: the loop is making progress (the systemd watchdog).
using ProgressCallback = std::function<void()>;

// One measurement cycle: grab a burst of daemon.burst_frames frames (freshest each), average those
// that pass the image-health check and show the same still scene, measure the average once against
// the baseline. nullopt when cancelled. `time` stamps the result; the
// caller fills alarm, version and config hash.
std::optional<CycleOutcome> runMeasurementCycle(FrameSource& source, MeasurementChain& chain,
                                                const config::DaemonConfig& config,
                                                std::chrono::system_clock::time_point time,
                                                const CancelCheck& cancelled, const ProgressCallback& progress);

// The clean-blade reference: the average of daemon.baseline_frames frames (healthy and still),
// accepted by the chain. pair: CV_32F grey eyes.
struct BaselineCapture {
    bool ok = false;
    std::string reason;  // when not ok
    StereoPair pair;
    StereoPair noise;  // one draw of the pair's own noise (empty with a single frame)
};
BaselineCapture captureBaselinePair(FrameSource& source, MeasurementChain& chain, const config::DaemonConfig& config,
                                    const CancelCheck& cancelled, const ProgressCallback& progress);

}  // namespace icewatch::daemon
