// The loop's pulse: pings keep it alive for the allowed gap, STOPPING=1 ends it, and the service
// manager still gets what it asked for and nothing it did not.
#include "daemon/scada/loop_heartbeat.hpp"

#include <vector>

#include <gtest/gtest.h>

namespace icewatch::daemon::scada {
namespace {

using namespace std::chrono_literals;
using Steady = std::chrono::steady_clock;

struct RecordingNotifier : Notifier {
    void notify(const std::string& message) override { messages.push_back(message); }
    std::optional<std::chrono::microseconds> watchdogInterval() const override { return watchdog; }
    std::vector<std::string> messages;
    std::optional<std::chrono::microseconds> watchdog;
};

TEST(LoopHeartbeat, AliveForTheAllowedGapAfterAPing) {
    RecordingNotifier systemd;
    LoopHeartbeat heartbeat(systemd, 3000ms);
    EXPECT_FALSE(heartbeat.alive(Steady::now())) << "no ping yet";
    heartbeat.notify("WATCHDOG=1");
    const auto pinged = Steady::now();
    EXPECT_TRUE(heartbeat.alive(pinged));
    EXPECT_TRUE(heartbeat.alive(pinged + 2900ms));
    EXPECT_FALSE(heartbeat.alive(pinged + 3100ms)) << "the loop stopped pinging";
    heartbeat.notify("STOPPING=1");
    EXPECT_FALSE(heartbeat.alive(Steady::now())) << "a stopping loop is not alive";
}

TEST(LoopHeartbeat, AsksForAPingEverySecondAndForwardsOnlyWhatSystemdWants) {
    RecordingNotifier systemd;  // no watchdog configured
    LoopHeartbeat heartbeat(systemd);
    ASSERT_TRUE(heartbeat.watchdogInterval());
    EXPECT_EQ(*heartbeat.watchdogInterval(), 2s) << "the loop pings at half of this";
    heartbeat.notify("READY=1\nSTATUS=measuring");
    heartbeat.notify("WATCHDOG=1");
    heartbeat.notify("STOPPING=1");
    EXPECT_EQ(systemd.messages, (std::vector<std::string>{"READY=1\nSTATUS=measuring", "STOPPING=1"}));
}

TEST(LoopHeartbeat, WithSystemdsWatchdogItsIntervalIsTheGap) {
    RecordingNotifier systemd;
    systemd.watchdog = 60s;
    LoopHeartbeat heartbeat(systemd);
    EXPECT_EQ(*heartbeat.watchdogInterval(), 2s);
    heartbeat.notify("WATCHDOG=1");
    EXPECT_EQ(systemd.messages, std::vector<std::string>{"WATCHDOG=1"});
    const auto now = Steady::now();
    EXPECT_TRUE(heartbeat.alive(now + 59s));
    EXPECT_FALSE(heartbeat.alive(now + 61s));

    systemd.watchdog = 1s;  // stricter than ours: systemd's wins
    EXPECT_EQ(*heartbeat.watchdogInterval(), 1s);
}

}  // namespace
}  // namespace icewatch::daemon::scada
