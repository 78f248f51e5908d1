#include "drivers/gpio/scada_outputs.hpp"

#include <filesystem>

#include <gtest/gtest.h>

#include "core/common/error.hpp"
#include "drivers/gpio/gpiod_output_line.hpp"
#include "tests/support/test_paths.hpp"

namespace icewatch::gpio {
namespace {

using alarm::AlarmLevel;

config::GpioConfig fakeConfig() {
    config::GpioConfig c;
    c.chip = "fake";
    return c;
}

TEST(ScadaOutputs, FailSafeMappingOfEveryLevel) {
    auto log = std::make_shared<TransitionLog>();
    {
        auto outputs = openScadaOutputs(fakeConfig(), log);
        EXPECT_TRUE(log->transitions().empty()) << "lines start de-energised: nothing to record";
        outputs->show(AlarmLevel::None);
        outputs->show(AlarmLevel::Warning);  // not wired out: no transition
        outputs->show(AlarmLevel::Alarm);
        outputs->show(AlarmLevel::Fault);
        outputs->show(AlarmLevel::Warning);
    }  // destroyed: fail-safe
    const std::vector<LineTransition> expected{
        {"alarm", true},  {"healthy", true},                      // none: both energised, healthy last
        {"alarm", false},                                         // alarm
        {"healthy", false},                                       // fault: healthy drops first
        {"alarm", true},  {"healthy", true},                      // warning
        {"healthy", false}, {"alarm", false},                     // shutdown
    };
    EXPECT_EQ(log->transitions(), expected);
}

TEST(ScadaOutputs, FakeFileRecordsForAnotherProcess) {
    const auto file = test::freshTempDir() / "gpio.log";
    auto c = fakeConfig();
    c.chip = "fake:" + file.string();
    {
        auto outputs = openScadaOutputs(c);
        outputs->show(AlarmLevel::Alarm);
    }
    const std::vector<LineTransition> expected{{"healthy", true}, {"healthy", false}};
    EXPECT_EQ(readTransitionFile(file), expected);
}

TEST(ScadaOutputs, NoneDrivesNothing) {
    auto c = fakeConfig();
    c.chip = "none";
    auto outputs = openScadaOutputs(c);
    EXPECT_TRUE(outputs->show(AlarmLevel::Alarm));
}

TEST(GpiodOutputLine, MissingChipIsNamed) {
    try {
        GpiodOutputLine line("/nonexistent/gpiochip9", 3, false, "icewatchd");
        FAIL() << "a missing chip must not open";
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), kExitUnavailable);
        EXPECT_NE(std::string(e.what()).find("/nonexistent/gpiochip9 line 3"), std::string::npos) << e.what();
    }
}

TEST(GpiodOutputLine, DrivesARealChipWhenThereIsOne) {
    // gpio-sim or real hardware; without a chip there is nothing to test against.
    const char* chip = std::getenv("ICEWATCH_TEST_GPIOCHIP");
    if (chip == nullptr) {
        GTEST_SKIP() << "set ICEWATCH_TEST_GPIOCHIP to a spare chip (e.g. a gpio-sim bank) to run this";
    }
    GpiodOutputLine line(chip, 0, true, "icewatch-test");
    EXPECT_FALSE(line.energised());
    EXPECT_TRUE(line.set(true));
    EXPECT_TRUE(line.energised());
}

}  // namespace
}  // namespace icewatch::gpio
