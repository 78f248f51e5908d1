#include "core/alarm/alarm_state.hpp"

#include <vector>

#include <gtest/gtest.h>

namespace icewatch::alarm {
namespace {

using std::chrono::minutes;

config::AlarmConfig volumeConfig() {
    config::AlarmConfig c;
    c.metric = "volume_mm3";
    c.warningSet = 100;
    c.warningClear = 80;
    c.alarmSet = 200;
    c.alarmClear = 150;
    c.warningHoldS = 0;
    c.alarmHoldS = 0;
    return c;
}

const TimePoint kT0 = TimePoint{} + std::chrono::hours(24 * 365 * 50);

TEST(AlarmState, StartsInFaultUntilSomethingIsMeasured) {
    AlarmStateMachine m(volumeConfig());
    EXPECT_EQ(m.level(), AlarmLevel::Fault);
    EXPECT_EQ(m.faultReason(), "no measurement yet");
    EXPECT_EQ(m.measured(0, 0, kT0), AlarmLevel::None);
}

TEST(AlarmState, RisesThroughTheLevelsAndFallsWithHysteresis) {
    AlarmStateMachine m(volumeConfig());
    const std::vector<double> series{0, 90, 100, 150, 199, 200, 300, 160, 151, 150, 120, 81, 80, 99, 0};
    const std::vector<AlarmLevel> expected{
        AlarmLevel::None,    AlarmLevel::None,    AlarmLevel::Warning, AlarmLevel::Warning, AlarmLevel::Warning,
        AlarmLevel::Alarm,   AlarmLevel::Alarm,   AlarmLevel::Alarm,   AlarmLevel::Alarm,   AlarmLevel::Warning,
        AlarmLevel::Warning, AlarmLevel::Warning, AlarmLevel::None,    AlarmLevel::None,    AlarmLevel::None};
    for (std::size_t i = 0; i < series.size(); ++i) {
        EXPECT_EQ(m.measured(series[i], 0, kT0 + minutes(10 * i)), expected[i]) << "step " << i << " value " << series[i];
    }
}

TEST(AlarmState, JumpsStraightToAlarmAndDropsStraightToNone) {
    AlarmStateMachine m(volumeConfig());
    EXPECT_EQ(m.measured(10, 0, kT0), AlarmLevel::None);
    EXPECT_EQ(m.measured(500, 0, kT0 + minutes(10)), AlarmLevel::Alarm);
    EXPECT_EQ(m.measured(10, 0, kT0 + minutes(20)), AlarmLevel::None);
}

TEST(AlarmState, ThicknessMetricIgnoresVolume) {
    auto c = volumeConfig();
    c.metric = "mean_thickness_mm";
    c.warningSet = 2;
    c.warningClear = 1;
    c.alarmSet = 5;
    c.alarmClear = 4;
    AlarmStateMachine m(c);
    EXPECT_EQ(m.measured(1e9, 0.5, kT0), AlarmLevel::None);
    EXPECT_EQ(m.measured(0, 2.5, kT0 + minutes(10)), AlarmLevel::Warning);
    EXPECT_EQ(m.measured(0, 6, kT0 + minutes(20)), AlarmLevel::Alarm);
}

TEST(AlarmState, TheUpperBoundCountsIceTheReadingCannotRuleOut) {
    // A single frame of a small bead on a turned blade: -65 805 ± 340 509 mm3 (README).
    const Reading wide{-65805, 340509, -0.4, 2.1};
    auto c = volumeConfig();
    c.warningSet = 50000;
    c.warningClear = 30000;
    c.alarmSet = 200000;
    c.alarmClear = 150000;
    EXPECT_EQ(AlarmStateMachine(c).measured(wide, kT0), AlarmLevel::None);
    c.judge = "upper_bound";
    EXPECT_DOUBLE_EQ(judgedValue(c, wide), 274704);
    AlarmStateMachine m(c);
    EXPECT_EQ(m.measured(wide, kT0), AlarmLevel::Alarm);
    // A narrow reading of the same estimate stays clear: only what may be there counts.
    EXPECT_EQ(m.measured({-65805, 20000, -0.4, 0.1}, kT0 + minutes(10)), AlarmLevel::None);
    // The thickness metric adds its own uncertainty, never the volume's.
    c.metric = "mean_thickness_mm";
    c.warningSet = 2;
    c.warningClear = 1;
    c.alarmSet = 5;
    c.alarmClear = 4;
    EXPECT_DOUBLE_EQ(judgedValue(c, wide), 1.7);
    EXPECT_EQ(AlarmStateMachine(c).measured({1e9, 1e9, 1.5, 0.6}, kT0), AlarmLevel::Warning);
}

TEST(AlarmState, AResetJudgesTheLastReadingUnderTheConfigOfTheMoment) {
    auto c = volumeConfig();
    c.latch = true;
    AlarmStateMachine m(c);
    EXPECT_EQ(m.measured({150, 100, 0, 0}, kT0), AlarmLevel::Warning);
    c.judge = "upper_bound";
    m.setConfig(c);
    EXPECT_EQ(m.reset(kT0 + minutes(1)), AlarmLevel::Alarm);
    c.judge = "estimate";
    m.setConfig(c);
    EXPECT_EQ(m.reset(kT0 + minutes(2)), AlarmLevel::Warning);
}

TEST(AlarmState, HoldTimeDelaysLoweringButNotRaising) {
    auto c = volumeConfig();
    c.alarmHoldS = 3600;
    c.warningHoldS = 1800;
    AlarmStateMachine m(c);
    EXPECT_EQ(m.measured(0, 0, kT0), AlarmLevel::None);
    EXPECT_EQ(m.measured(250, 0, kT0 + minutes(10)), AlarmLevel::Alarm);  // raising: at once
    EXPECT_EQ(m.measured(0, 0, kT0 + minutes(20)), AlarmLevel::Alarm);
    EXPECT_EQ(m.measured(0, 0, kT0 + minutes(69)), AlarmLevel::Alarm);    // 59 min held
    EXPECT_EQ(m.measured(120, 0, kT0 + minutes(70)), AlarmLevel::Warning);  // 60 min held
    EXPECT_EQ(m.measured(0, 0, kT0 + minutes(80)), AlarmLevel::Warning);
    EXPECT_EQ(m.measured(0, 0, kT0 + minutes(100)), AlarmLevel::None);
}

TEST(AlarmState, LatchedAlarmStaysUntilReset) {
    auto c = volumeConfig();
    c.latch = true;
    AlarmStateMachine m(c);
    EXPECT_EQ(m.measured(300, 0, kT0), AlarmLevel::Alarm);
    EXPECT_TRUE(m.latched());
    EXPECT_EQ(m.measured(0, 0, kT0 + minutes(10)), AlarmLevel::Alarm);
    EXPECT_EQ(m.measured(0, 0, kT0 + minutes(600)), AlarmLevel::Alarm);
    EXPECT_EQ(m.reset(kT0 + minutes(601)), AlarmLevel::None);
    EXPECT_FALSE(m.latched());
}

TEST(AlarmState, ResetDoesNotHideIceStillPresent) {
    auto c = volumeConfig();
    c.latch = true;
    AlarmStateMachine m(c);
    m.measured(300, 0, kT0);
    EXPECT_EQ(m.reset(kT0 + minutes(1)), AlarmLevel::Alarm);
    m.measured(160, 0, kT0 + minutes(10));
    EXPECT_EQ(m.reset(kT0 + minutes(11)), AlarmLevel::Alarm);  // above alarm_clear: still ice
    m.measured(120, 0, kT0 + minutes(20));
    EXPECT_EQ(m.reset(kT0 + minutes(21)), AlarmLevel::Warning);
}

TEST(AlarmState, FaultIsNeverNoIceAndKeepsTheIceLevel) {
    AlarmStateMachine m(volumeConfig());
    m.measured(120, 0, kT0);
    EXPECT_EQ(m.fault("camera offline"), AlarmLevel::Fault);
    EXPECT_EQ(m.faultReason(), "camera offline");
    EXPECT_EQ(m.iceLevel(), AlarmLevel::Warning);
    // The first measurement after the fault is judged against the level before it (hysteresis).
    EXPECT_EQ(m.measured(90, 0, kT0 + minutes(30)), AlarmLevel::Warning);
    EXPECT_FALSE(m.faulted());
    AlarmStateMachine fresh(volumeConfig());
    EXPECT_EQ(fresh.fault("no baseline"), AlarmLevel::Fault);
    EXPECT_EQ(fresh.reset(kT0), AlarmLevel::Fault);  // a reset does not clear a fault
}

TEST(AlarmState, NewThresholdsApplyFromTheNextMeasurement) {
    AlarmStateMachine m(volumeConfig());
    EXPECT_EQ(m.measured(120, 0, kT0), AlarmLevel::Warning);
    auto c = volumeConfig();
    c.warningSet = 1000;
    c.warningClear = 900;
    c.alarmSet = 2000;
    c.alarmClear = 1500;
    m.setConfig(c);
    EXPECT_EQ(m.level(), AlarmLevel::Warning);
    EXPECT_EQ(m.measured(120, 0, kT0 + minutes(10)), AlarmLevel::None);
}

TEST(AlarmState, LevelNames) {
    EXPECT_STREQ(toString(AlarmLevel::None), "none");
    EXPECT_STREQ(toString(AlarmLevel::Warning), "warning");
    EXPECT_STREQ(toString(AlarmLevel::Alarm), "alarm");
    EXPECT_STREQ(toString(AlarmLevel::Fault), "fault");
}

}  // namespace
}  // namespace icewatch::alarm
