#include "drivers/log/log.hpp"

#include <gtest/gtest.h>
#include <spdlog/sinks/ostream_sink.h>

#include <sstream>

namespace icewatch::log {
namespace {

TEST(StateLog, LogsOncePerChangeOfState) {
    std::ostringstream out;
    auto sink = std::make_shared<spdlog::sinks::ostream_sink_mt>(out);
    auto logger = std::make_shared<spdlog::logger>("camera-test", sink);
    logger->set_pattern("[%n] %v");
    StateLog state(logger);
    EXPECT_TRUE(state.report("offline", spdlog::level::warn, "camera offline"));
    for (int retry = 0; retry < 50; ++retry) {
        EXPECT_FALSE(state.report("offline", spdlog::level::warn, "camera offline"));
    }
    EXPECT_TRUE(state.report("ok", spdlog::level::info, "camera back"));
    EXPECT_EQ(out.str(), "[camera-test] camera offline\n[camera-test] camera back\n");
}

TEST(Log, SubsystemLoggersAreShared) {
    setup("warn");
    auto a = get("subsystem-a");
    EXPECT_EQ(a, get("subsystem-a"));
    EXPECT_EQ(a->level(), spdlog::level::warn);
    setLevel("debug");
    EXPECT_EQ(a->level(), spdlog::level::debug);
}

}  // namespace
}  // namespace icewatch::log
