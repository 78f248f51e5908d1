// Chooses the production implementations of the daemon's two seams. This build carries neither a
// V4L2 capture nor a volume chain yet, so the parts say so in every answer: the camera reads as
// offline with that reason and no baseline can be set, which the daemon reports as a fault and
// no_baseline (never as "no ice").
#include "daemon/wiring.hpp"

#include "daemon/sha256.hpp"

namespace icewatch::daemon {

namespace {

class MissingCapture : public FrameSource {
public:
    explicit MissingCapture(std::string device) : why_("no capture driver in this build for " + device) {}
    bool open(std::string& error) override {
        error = why_;
        return false;
    }
    std::optional<StereoPair> grabFreshest(std::string& error) override {
        error = why_;
        return std::nullopt;
    }
    CameraState health(std::string& detail) override {
        detail = why_;
        return CameraState::Offline;
    }
    void close() override {}

private:
    std::string why_;
};

class MissingChain : public MeasurementChain {
public:
    explicit MissingChain(std::string calibrationSha256) : calibrationSha256_(std::move(calibrationSha256)) {}
    std::string calibrationSha256() const override { return calibrationSha256_; }
    ChainResult setBaseline(const StereoPair&) override { return failed(); }
    bool hasBaseline() const override { return false; }
    ChainResult estimate(const StereoPair&) override { return failed(); }

private:
    static ChainResult failed() {
        ChainResult r;
        r.status = ChainResult::Status::Failed;
        r.reason = "no volume chain in this build";
        return r;
    }
    std::string calibrationSha256_;
};

}  // namespace

std::unique_ptr<FrameSource> makeFrameSource(const config::Config& config) {
    return std::make_unique<MissingCapture>(config.camera.device);
}

std::unique_ptr<MeasurementChain> makeMeasurementChain(const config::Config& config) {
    return std::make_unique<MissingChain>(sha256OfFile(config.daemon.calibration).value_or(""));
}

}  // namespace icewatch::daemon
