#pragma once

#include <array>
#include <cstdint>

#include <nlohmann/json.hpp>

namespace icewatch::daemon::scada {

// The Modbus register map, version 2: a contract with SCADA integrators (README "SCADA
// integration"). Later versions only add addresses; the version register says which map it is.
// Addresses are 0-based; 32-bit values take two registers, high word first; floats are IEEE 754
// single precision.
// Version 2 added the mean thickness's uncertainty (registers 16-17), so that a client can judge
// the thickness on what a reading cannot rule out, as the daemon's alarm.judge upper_bound does.
inline constexpr std::uint16_t kMapVersion = 2;

// Discrete inputs (function 02).
enum DiscreteInput : int {
    kIceAlarm = 0,     // alarm level is alarm
    kIceWarning = 1,   // alarm level is warning or alarm
    kFault = 2,        // alarm level is fault: camera, measurement or no baseline
    kStale = 3,        // the result is older than two measurement intervals
    kAlarmLatched = 4, // alarm.latch holds the alarm until a reset
    kDiscreteInputCount = 5,
};

// Input registers (function 04).
enum InputRegister : int {
    kVersionRegister = 0,
    kStatusRegister = 1,      // 0 ok, 1 refused, 2 no baseline, 3 fault
    kAlarmLevelRegister = 2,  // 0 clear, 1 warning, 2 alarm, 3 fault
    kHeartbeatRegister = 3,   // +1 a second while the service loop is healthy, wraps at 65535
    kVolumeRegister = 4,      // float32 mm³, NaN when there is none
    kUncertaintyRegister = 6, // float32 mm³
    kMeanThicknessRegister = 8,
    kMaxThicknessRegister = 10,
    kResultTimeRegister = 12,   // uint32 Unix seconds
    kResultCountRegister = 14,  // uint32 results published since the daemon started
    kMeanThicknessUncertaintyRegister = 16,  // float32 mm, k = 2 (map version 2)
    kInputRegisterCount = 18,
};

// Coils (functions 01, 05, 15), only with scada.modbus.allow_writes. Writing 1 asks; they read 0.
enum Coil : int {
    kMeasureNowCoil = 0,  // as SIGUSR1
    kResetAlarmCoil = 1,  // as SIGUSR2
    kCoilCount = 2,
};

// The inputs and registers of one moment, handed over as one piece so that a client never reads
// the volume of one cycle with the status of another.
struct RegisterImage {
    std::array<std::uint8_t, kDiscreteInputCount> inputs{};
    std::array<std::uint16_t, kInputRegisterCount> registers{};
};

// Before the first result: fault and stale, no values, time and count 0.
RegisterImage emptyImage();

// The image of a latest.json document; resultCount goes to registers 14-15. Heartbeat and stale
// are left for the server, which keeps them current between results.
RegisterImage imageOf(const nlohmann::json& document, bool alarmLatched, std::uint32_t resultCount);

}  // namespace icewatch::daemon::scada
