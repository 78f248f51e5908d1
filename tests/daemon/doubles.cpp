#include "tests/daemon/doubles.hpp"

#include "daemon/iso_time.hpp"

namespace icewatch::daemon::test {

StereoPair texturedPair(double brightness, int seed) {
    cv::Mat grey(96, 128, CV_8UC1);
    cv::RNG rng(static_cast<std::uint64_t>(seed));
    rng.fill(grey, cv::RNG::UNIFORM, 40, 200);
    cv::Mat scaled;
    grey.convertTo(scaled, CV_8U, brightness);
    cv::Mat bgr;
    cv::merge(std::vector<cv::Mat>{scaled, scaled, scaled}, bgr);
    return {bgr, bgr.clone()};
}

bool ScriptedSource::open(std::string& error) {
    if (!plugged) {
        error = "no such device";
        return false;
    }
    closed = false;
    return true;
}

std::optional<StereoPair> ScriptedSource::grabFreshest(std::string& error) {
    ++grabs;
    if (unplugAtGrab != 0 && grabs == unplugAtGrab) {
        plugged = false;
    }
    if (!plugged) {
        error = "ENODEV: the camera went away";
        return std::nullopt;
    }
    return frame ? frame(grabs) : texturedPair();
}

CameraState ScriptedSource::health(std::string& detail) {
    detail = plugged ? "" : "no such device";
    return plugged ? CameraState::Ok : CameraState::Offline;
}

ChainResult ScriptedChain::setBaseline(StereoPair clean, StereoPair noise) {
    for (int i = 0; i < stages && progress; ++i) progress();
    if (clean.left.empty()) {
        return refusedResult("empty baseline");
    }
    baselineSet = true;
    baselineNoise = std::move(noise);
    ChainResult r;
    r.status = ChainResult::Status::Ok;
    return r;
}

ChainResult ScriptedChain::estimate(StereoPair current, StereoPair /*noise*/) {
    ++calls;
    for (int i = 0; i < stages && progress; ++i) progress();
    if (!baselineSet) {
        ChainResult r;
        r.status = ChainResult::Status::Failed;
        r.reason = "estimate without a baseline";
        return r;
    }
    ChainResult r = script ? script(calls, current) : okResult(1000.0);
    if (r.status == ChainResult::Status::Ok && r.pictures.left.empty()) {
        current.left.convertTo(r.pictures.left, CV_8U);  // an averaged capture is float
        r.pictures.disparity = cv::Mat(current.left.size(), CV_8UC3, cv::Scalar(255, 0, 0));
        r.pictures.thickness = cv::Mat(current.left.size(), CV_8UC3, cv::Scalar(0, 0, 255));
    }
    return r;
}

ChainResult okResult(double volumeMm3, double uncertaintyMm3, double meanThicknessMm) {
    ChainResult r;
    r.status = ChainResult::Status::Ok;
    r.volumeMm3 = volumeMm3;
    r.uncertaintyMm3 = uncertaintyMm3;
    r.meanThicknessMm = meanThicknessMm;
    r.meanThicknessUncertaintyMm = meanThicknessMm * uncertaintyMm3 / volumeMm3;  // over the same area
    r.maxThicknessMm = 3 * meanThicknessMm;
    r.iceAreaMm2 = volumeMm3 / meanThicknessMm;
    r.beyondOutlineMm3 = 0.1 * volumeMm3;
    r.validPercent = 90.0;
    r.timingsMs = {{"match", 12.5}, {"integrate", 0.5}};
    return r;
}

ChainResult refusedResult(const std::string& reason) {
    ChainResult r;
    r.status = ChainResult::Status::Refused;
    r.reason = reason;
    return r;
}

config::Config testConfig(const std::filesystem::path& stateDir) {
    config::Config c;
    c.daemon.intervalS = 600;
    c.daemon.burstFrames = 3;
    c.daemon.minFrames = 2;
    c.daemon.cameraCheckS = 5;
    c.daemon.stateDir = stateDir.string();
    c.alarm.warningSet = 100;
    c.alarm.warningClear = 80;
    c.alarm.alarmSet = 200;
    c.alarm.alarmClear = 150;
    c.alarm.warningHoldS = 0;
    c.alarm.alarmHoldS = 0;
    c.gpio.chip = "fake";
    c.http.port = 0;
    c.http.tokenFile = (stateDir / "http-token").string();  // never the machine's /etc/icewatch
    return c;
}

TimePoint testEpoch() {
    return *parseIsoUtc("2026-01-01T00:00:00Z");
}

}  // namespace icewatch::daemon::test
