#pragma once

#include <filesystem>
#include <optional>

#include "core/pictures/picture_scale.hpp"
#include "core/volume/chain.hpp"
#include "daemon/measurement_chain.hpp"

namespace icewatch::daemon {

// MeasurementChain over the volume chain (core/volume): the baseline is kept as a measured
// surface, each estimate measures the current pair and compares.
class VolumeMeasurementChain : public MeasurementChain {
public:
    // Throws Error when the calibration file is missing or invalid, or the parameters are unusable.
    // `pictures`: the scale of the pictures of each measurement (ok or refused).
    // `stereo`: the matcher's parameters (the configuration's "stereo" section).
    VolumeMeasurementChain(const std::filesystem::path& calibrationFile, const volume::Parameters& parameters,
                           const pictures::PictureScale& pictures = {}, const stereo::Parameters& stereo = {});
    VolumeMeasurementChain(const calib::StereoCalibration& calibration, std::string calibrationSha256,
                           const volume::Parameters& parameters, const pictures::PictureScale& pictures = {},
                           const stereo::Parameters& stereo = {});

    std::string calibrationSha256() const override { return calibrationSha256_; }
    ChainResult setBaseline(StereoPair clean, StereoPair noise) override;
    bool hasBaseline() const override { return baseline_.has_value(); }
    ChainResult estimate(StereoPair current, StereoPair noise) override;
    void onProgress(std::function<void()> progress) override { chain_.onStageDone(std::move(progress)); }

private:
    std::string calibrationSha256_;
    double minValidPercent_;
    double coverageFactor_;
    int maxDisparity_;
    pictures::PictureScale pictureScale_;
    volume::VolumeChain chain_;
    std::optional<volume::Surface> baseline_;
};

}  // namespace icewatch::daemon
