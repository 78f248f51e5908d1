// The daemon's measurement through the volume chain. A frame that does not fit the calibration
// (another camera mode) is a failure of the set-up, reported as Failed (a fault), while the
// chain's own refusals (dark, no texture, registration) are Refused and leave the alarm alone.
#include "daemon/volume_measurement_chain.hpp"

#include "core/common/error.hpp"
#include "core/pictures/measurement_pictures.hpp"
#include "daemon/sha256.hpp"
#include "drivers/log/log.hpp"

namespace icewatch::daemon {

namespace {
void addTimings(std::map<std::string, double>& out, const volume::Timings& timings, const std::string& prefix) {
    for (const auto& [stage, ms] : timings) out[prefix + stage] += ms;
}

ChainResult failure(ChainResult::Status status, std::string reason) {
    ChainResult r;
    r.status = status;
    r.reason = std::move(reason);
    return r;
}
}  // namespace

VolumeMeasurementChain::VolumeMeasurementChain(const std::filesystem::path& calibrationFile,
                                               const volume::Parameters& parameters,
                                               const pictures::PictureScale& pictures, const stereo::Parameters& stereo)
    : VolumeMeasurementChain(calib::loadCalibration(calibrationFile), sha256OfFile(calibrationFile).value_or(""),
                             parameters, pictures, stereo) {}

VolumeMeasurementChain::VolumeMeasurementChain(const calib::StereoCalibration& calibration,
                                               std::string calibrationSha256, const volume::Parameters& parameters,
                                               const pictures::PictureScale& pictures, const stereo::Parameters& stereo)
    : calibrationSha256_(std::move(calibrationSha256)),
      minValidPercent_(parameters.minValidPercent),
      coverageFactor_(parameters.coverageFactor),
      maxDisparity_(parameters.maxDisparity),
      pictureScale_(pictures),
      chain_(calibration, parameters, [] { return std::chrono::steady_clock::now(); }, stereo) {}

ChainResult VolumeMeasurementChain::setBaseline(StereoPair clean, StereoPair noise) {
    try {
        volume::Surface surface = chain_.measureSurface(std::move(clean), std::move(noise));
        if (surface.validPercent < minValidPercent_) {
            return failure(ChainResult::Status::Refused,
                           "baseline has " + std::to_string(static_cast<int>(surface.validPercent)) +
                               " % valid disparities in the region, " +
                               std::to_string(static_cast<int>(minValidPercent_)) + " % needed");
        }
        if (surface.outlineBackgroundPercent > 0) {
            // Said once per baseline: the engineer who drew the outline sees what the chain made of it.
            log::get("chain")->info("the drawn outline (volume.roi_polygon) held {:.1f} % background (featureless "
                                    "sky beside the object, or a table it stands above), left out of the region",
                                    surface.outlineBackgroundPercent);
        }
        baseline_ = std::move(surface);
    } catch (const InvalidInput& e) {
        return failure(ChainResult::Status::Failed, e.what());
    }
    ChainResult ok;
    ok.status = ChainResult::Status::Ok;
    return ok;
}

ChainResult VolumeMeasurementChain::estimate(StereoPair current, StereoPair noise) {
    if (!baseline_) {
        return failure(ChainResult::Status::Failed, "no baseline set");
    }
    volume::Surface surface;
    try {
        surface = chain_.measureSurface(std::move(current), *baseline_, std::move(noise));
    } catch (const InvalidInput& e) {
        return failure(ChainResult::Status::Failed, e.what());
    }
    const volume::VolumeResult v = chain_.estimate(*baseline_, surface);
    ChainResult r;
    addTimings(r.timingsMs, surface.timingsMs, "");
    addTimings(r.timingsMs, v.timingsMs, "");
    // A refusal keeps its pictures too: that is when a person wants to look.
    pictures::MeasurementPictures drawn = pictures::drawMeasurement(surface, v, maxDisparity_, pictureScale_);
    r.pictures = {std::move(drawn.left), std::move(drawn.disparity), std::move(drawn.thickness)};
    if (!v.ok) {
        r.status = ChainResult::Status::Refused;
        r.reason = v.reason;
        return r;
    }
    r.status = ChainResult::Status::Ok;
    r.volumeMm3 = v.volumeMm3;
    r.uncertaintyMm3 = v.uncertaintyMm3;
    r.coverageFactor = coverageFactor_;
    r.meanThicknessMm = v.meanThicknessMm;
    r.meanThicknessUncertaintyMm = v.meanThicknessUncertaintyMm;
    r.maxThicknessMm = v.maxThicknessMm;
    r.iceAreaMm2 = v.iceAreaMm2;
    r.beyondOutlineMm3 = v.beyondOutlineMm3;
    r.validPercent = v.validPercent;
    return r;
}

}  // namespace icewatch::daemon
