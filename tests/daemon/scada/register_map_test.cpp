// The register map as a contract: each address holds what the README table says, encoded as it
// says (float32 and uint32 high word first).
#include "daemon/scada/register_map.hpp"

#include <bit>
#include <cmath>

#include <gtest/gtest.h>

namespace icewatch::daemon::scada {
namespace {

nlohmann::json okDocument() {
    return {{"schema", 1},
            {"time", "2026-01-01T00:10:00Z"},
            {"status", "ok"},
            {"volume_mm3", 427174.25},
            {"uncertainty_mm3", 21000.5},
            {"mean_thickness_mm", 3.75},
            {"max_thickness_mm", 12.5},
            {"mean_thickness_uncertainty_mm", 0.1875},
            {"alarm", "warning"}};
}

// High word first, IEEE 754 single precision.
float floatAt(const RegisterImage& image, int address) {
    const auto i = static_cast<std::size_t>(address);
    return std::bit_cast<float>((static_cast<std::uint32_t>(image.registers[i]) << 16) | image.registers[i + 1]);
}

TEST(RegisterMap, ValuesOfAResult) {
    const RegisterImage image = imageOf(okDocument(), false, 0x12345678u);
    EXPECT_EQ(image.registers[kVersionRegister], 2);
    EXPECT_EQ(image.registers[kStatusRegister], 0);
    EXPECT_EQ(image.registers[kAlarmLevelRegister], 1);
    EXPECT_FLOAT_EQ(floatAt(image, kVolumeRegister), 427174.25f);
    EXPECT_FLOAT_EQ(floatAt(image, kUncertaintyRegister), 21000.5f);
    EXPECT_FLOAT_EQ(floatAt(image, kMeanThicknessRegister), 3.75f);
    EXPECT_FLOAT_EQ(floatAt(image, kMaxThicknessRegister), 12.5f);
    // 2026-01-01T00:10:00Z = 1767226200 = 0x6955BB58, high word first.
    EXPECT_EQ(image.registers[kResultTimeRegister], 0x6955);
    EXPECT_EQ(image.registers[kResultTimeRegister + 1], 0xBB58);
    EXPECT_EQ(image.registers[kResultCountRegister], 0x1234);
    EXPECT_EQ(image.registers[kResultCountRegister + 1], 0x5678);
    EXPECT_FLOAT_EQ(floatAt(image, kMeanThicknessUncertaintyRegister), 0.1875f);
    EXPECT_EQ(image.inputs, (std::array<std::uint8_t, 5>{0, 1, 0, 1, 0}));
}

TEST(RegisterMap, FloatsAreBigEndianIeee754) {
    // 1.0f is 0x3F800000: the high word 0x3F80 comes first.
    nlohmann::json document = okDocument();
    document["volume_mm3"] = 1.0;
    const RegisterImage image = imageOf(document, false, 1);
    EXPECT_EQ(image.registers[kVolumeRegister], 0x3F80);
    EXPECT_EQ(image.registers[kVolumeRegister + 1], 0x0000);
}

TEST(RegisterMap, AbsentFiguresAreNaN) {
    nlohmann::json document = okDocument();
    document["status"] = "refused";
    for (const char* key : {"volume_mm3", "uncertainty_mm3", "mean_thickness_mm", "max_thickness_mm",
                            "mean_thickness_uncertainty_mm"}) {
        document[key] = nullptr;
    }
    const RegisterImage image = imageOf(document, false, 1);
    EXPECT_EQ(image.registers[kStatusRegister], 1);
    for (int address : {kVolumeRegister, kUncertaintyRegister, kMeanThicknessRegister, kMaxThicknessRegister,
                        kMeanThicknessUncertaintyRegister}) {
        EXPECT_TRUE(std::isnan(floatAt(image, address))) << address;
    }
}

TEST(RegisterMap, StatusAndAlarmCodes) {
    const std::vector<std::pair<std::string, int>> statuses{{"ok", 0}, {"refused", 1}, {"no_baseline", 2}, {"fault", 3}};
    for (const auto& [status, code] : statuses) {
        nlohmann::json document = okDocument();
        document["status"] = status;
        EXPECT_EQ(imageOf(document, false, 1).registers[kStatusRegister], code) << status;
    }
    // alarm level -> register 2 and discrete inputs 0 (alarm), 1 (warning or alarm), 2 (fault)
    struct Case {
        std::string alarm;
        int code;
        std::uint8_t iceAlarm, iceWarning, fault;
    };
    for (const auto& c : std::vector<Case>{{"none", 0, 0, 0, 0}, {"warning", 1, 0, 1, 0}, {"alarm", 2, 1, 1, 0},
                                          {"fault", 3, 0, 0, 1}}) {
        nlohmann::json document = okDocument();
        document["alarm"] = c.alarm;
        const RegisterImage image = imageOf(document, true, 1);
        EXPECT_EQ(image.registers[kAlarmLevelRegister], c.code) << c.alarm;
        EXPECT_EQ(image.inputs[kIceAlarm], c.iceAlarm) << c.alarm;
        EXPECT_EQ(image.inputs[kIceWarning], c.iceWarning) << c.alarm;
        EXPECT_EQ(image.inputs[kFault], c.fault) << c.alarm;
        EXPECT_EQ(image.inputs[kAlarmLatched], 1) << c.alarm;
    }
}

TEST(RegisterMap, BeforeTheFirstResultEverythingSaysFault) {
    const RegisterImage image = emptyImage();
    EXPECT_EQ(image.registers[kVersionRegister], 2);
    EXPECT_EQ(image.registers[kStatusRegister], 3);
    EXPECT_EQ(image.registers[kAlarmLevelRegister], 3);
    EXPECT_TRUE(std::isnan(floatAt(image, kVolumeRegister)));
    EXPECT_TRUE(std::isnan(floatAt(image, kMeanThicknessUncertaintyRegister)));
    EXPECT_EQ(image.registers[kResultTimeRegister], 0);
    EXPECT_EQ(image.registers[kResultTimeRegister + 1], 0);
    EXPECT_EQ(image.registers[kResultCountRegister + 1], 0);
    EXPECT_EQ(image.inputs, (std::array<std::uint8_t, 5>{0, 0, 1, 1, 0}));
}

}  // namespace
}  // namespace icewatch::daemon::scada
