// Turns a result document into the register map's values. The document is the one source: the
// registers say what latest.json and MQTT say, encoded with libmodbus's word macro.
#include "daemon/scada/register_map.hpp"

#include <modbus.h>

#include <bit>
#include <limits>
#include <string>

#include "daemon/iso_time.hpp"

namespace icewatch::daemon::scada {

namespace {

std::uint16_t statusCode(const nlohmann::json& status) {
    if (status == "ok") return 0;
    if (status == "refused") return 1;
    if (status == "no_baseline") return 2;
    return 3;
}

std::uint16_t alarmCode(const nlohmann::json& alarm) {
    if (alarm == "none") return 0;
    if (alarm == "warning") return 1;
    if (alarm == "alarm") return 2;
    return 3;
}

void setUint32(RegisterImage& image, int address, std::uint32_t value) {
    MODBUS_SET_INT32_TO_INT16(image.registers.data(), address, value);
}

// Not modbus_set_float_abcd: libmodbus 3.1.6 swaps the bytes of each word there (fixed in
// 3.1.7), so a float goes out as its IEEE 754 bits under the map's uint32 rule.
void setFloat(RegisterImage& image, int address, const nlohmann::json& value) {
    const float f = value.is_number() ? value.get<float>() : std::numeric_limits<float>::quiet_NaN();
    setUint32(image, address, std::bit_cast<std::uint32_t>(f));
}

std::uint32_t unixSeconds(const nlohmann::json& time) {
    if (!time.is_string()) return 0;
    const auto parsed = parseIsoUtc(time.get<std::string>());
    if (!parsed) return 0;
    const auto seconds = std::chrono::duration_cast<std::chrono::seconds>(parsed->time_since_epoch()).count();
    return seconds < 0 ? 0 : static_cast<std::uint32_t>(seconds);
}

const nlohmann::json& field(const nlohmann::json& document, const char* key) {
    static const nlohmann::json kNull;
    const auto it = document.find(key);
    return it == document.end() ? kNull : *it;
}

}  // namespace

RegisterImage emptyImage() {
    return imageOf(nlohmann::json::object(), false, 0);
}

RegisterImage imageOf(const nlohmann::json& document, bool alarmLatched, std::uint32_t resultCount) {
    RegisterImage image;
    const std::uint16_t alarm = alarmCode(field(document, "alarm"));
    image.inputs[kIceAlarm] = alarm == 2;
    image.inputs[kIceWarning] = alarm == 1 || alarm == 2;
    image.inputs[kFault] = alarm == 3;
    image.inputs[kStale] = 1;  // until the server has looked at the time
    image.inputs[kAlarmLatched] = alarmLatched;

    image.registers[kVersionRegister] = kMapVersion;
    image.registers[kStatusRegister] = statusCode(field(document, "status"));
    image.registers[kAlarmLevelRegister] = alarm;
    setFloat(image, kVolumeRegister, field(document, "volume_mm3"));
    setFloat(image, kUncertaintyRegister, field(document, "uncertainty_mm3"));
    setFloat(image, kMeanThicknessRegister, field(document, "mean_thickness_mm"));
    setFloat(image, kMaxThicknessRegister, field(document, "max_thickness_mm"));
    setUint32(image, kResultTimeRegister, unixSeconds(field(document, "time")));
    setUint32(image, kResultCountRegister, resultCount);
    setFloat(image, kMeanThicknessUncertaintyRegister, field(document, "mean_thickness_uncertainty_mm"));
    return image;
}

}  // namespace icewatch::daemon::scada
