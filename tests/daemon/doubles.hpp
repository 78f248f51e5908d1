#pragma once

// Test doubles of the daemon's two seams and a configuration for simulated days.
#include <deque>
#include <functional>
#include <memory>
#include <string>

#include <opencv2/core.hpp>

#include "core/config/config.hpp"
#include "daemon/clock.hpp"
#include "daemon/frame_source.hpp"
#include "daemon/measurement_chain.hpp"

namespace icewatch::daemon::test {

// A small textured pair that passes the image-health check; brightness scales it (0.1 = night).
StereoPair texturedPair(double brightness = 1.0, int seed = 1);

// A camera that can be unplugged and plugged back, mid-burst if wanted.
class ScriptedSource : public FrameSource {
public:
    bool open(std::string& error) override;
    std::optional<StereoPair> grabFreshest(std::string& error) override;
    CameraState health(std::string& detail) override;
    void close() override {
        closed = true;
        if (closedOutside) *closedOutside = true;
    }

    bool plugged = true;
    int unplugAtGrab = 0;                     // 1-based grab number at which the cable is pulled
    std::function<StereoPair(int grab)> frame;  // default: texturedPair()
    int grabs = 0;
    bool closed = false;
    std::shared_ptr<bool> closedOutside;  // still readable after the daemon destroyed the source
};

// A volume chain whose answers are scripted per call (call numbers start at 1).
class ScriptedChain : public MeasurementChain {
public:
    std::string calibrationSha256() const override { return calibration; }
    ChainResult setBaseline(StereoPair clean, StereoPair noise) override;
    bool hasBaseline() const override { return baselineSet; }
    ChainResult estimate(StereoPair current, StereoPair noise) override;
    void onProgress(std::function<void()> hook) override { progress = std::move(hook); }

    std::string calibration = "c0ffee";
    int stages = 0;  // setBaseline and estimate report this many stages done before they answer
    std::function<void()> progress;
    bool baselineSet = true;
    StereoPair baselineNoise;  // the noise draw the last setBaseline was given
    int calls = 0;
    std::function<ChainResult(int call, const StereoPair&)> script;  // default: 1000 mm³ ± 50
};

ChainResult okResult(double volumeMm3, double uncertaintyMm3 = 50.0, double meanThicknessMm = 1.0);
ChainResult refusedResult(const std::string& reason);

// interval 600 s, burst 3, min 2 frames, camera checked every 5 s, hysteresis thresholds
// warning 100/80 and alarm 200/150 mm³ without hold times, fake GPIO.
config::Config testConfig(const std::filesystem::path& stateDir);

// 2026-01-01T00:00:00Z
TimePoint testEpoch();

}  // namespace icewatch::daemon::test
