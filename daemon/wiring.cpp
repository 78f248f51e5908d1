// Chooses the production implementations of the daemon's two seams: the V4L2 capture (or the
// fake uvcvideo device for fake:DIR) and the volume chain with the configured calibration.
#include "daemon/wiring.hpp"

#include <system_error>

#include "core/common/error.hpp"
#include "daemon/v4l2_frame_source.hpp"
#include "daemon/volume_measurement_chain.hpp"

namespace icewatch::daemon {

std::unique_ptr<FrameSource> makeFrameSource(const config::Config& config) {
    return std::make_unique<V4l2FrameSource>(config.camera);
}

std::unique_ptr<MeasurementChain> makeMeasurementChain(const config::Config& config) {
    const std::string& file = config.calibration.file;
    std::error_code error;
    if (!std::filesystem::exists(file, error)) {
        // A box fresh from the package: say what to do, not just what is absent.
        throw Error(kExitNoInput, "no calibration: run icewatch calibrate --pairs DIR --board 9x6 --square-mm SIZE "
                                  "--out " + file + " (README, Calibration), then systemctl reload icewatchd");
    }
    try {
        return std::make_unique<VolumeMeasurementChain>(file, config.volume, config.pictures, config.stereo);
    } catch (const Error& e) {
        throw Error(e.code(), std::string("unusable calibration: ") + e.what());
    }
}

std::optional<std::string> missingGpioChip(const config::GpioConfig& config) {
    const std::string& chip = config.chip;
    // libgpiod also takes labels and numbers; a name or path that names no device is the case a
    // box without its I/O board (or a desk PC) meets, so it gets the plain answer.
    const bool isPath = chip.rfind('/', 0) == 0;
    if (!isPath && chip.rfind("gpiochip", 0) != 0) return std::nullopt;
    const std::filesystem::path device = isPath ? chip : "/dev/" + chip;
    std::error_code error;
    if (std::filesystem::exists(device, error)) return std::nullopt;
    return "no GPIO chip " + chip + " (" + device.string() + " does not exist; gpio.chip)";
}

std::unique_ptr<gpio::ScadaOutputs> openAlarmOutputs(const config::GpioConfig& config) {
    if (const auto missing = missingGpioChip(config)) {
        throw Error(kExitUnavailable, *missing);
    }
    return gpio::openScadaOutputs(config);
}

}  // namespace icewatch::daemon
