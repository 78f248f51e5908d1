// The calibration loader: any text gives a calibration or an Error with exit status 65.
#include <cstdlib>
#include <string>

#include "core/calib/stereo_calibration.hpp"
#include "core/common/error.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    try {
        icewatch::calib::parseCalibration(std::string(reinterpret_cast<const char*>(data), size), "fuzz.yaml");
    } catch (const icewatch::Error& e) {
        if (e.code() != icewatch::kExitDataErr) std::abort();
    }
    return 0;
}
