// The icewatch program as a person or a script meets it: exit statuses and messages.
#include <fstream>

#include <gtest/gtest.h>

#include "core/common/exit_codes.hpp"
#include "tests/support/run_program.hpp"
#include "tests/support/test_paths.hpp"

namespace icewatch {
namespace {

std::string icewatchBin() { return (test::binDir() / "icewatch").string(); }

TEST(Cli, HelpAndUnknownSubcommand) {
    auto help = test::runProgram({icewatchBin(), "--help"});
    EXPECT_EQ(help.status, 0);
    EXPECT_NE(help.out.find("config"), std::string::npos);
    auto bad = test::runProgram({icewatchBin(), "frobnicate"});
    EXPECT_EQ(bad.status, kExitUsage);
}

TEST(Cli, ConfigCheckAcceptsTheShippedFile) {
    auto r = test::runProgram({icewatchBin(), "config", "check", (test::sourceDir() / "config/icewatch.json").string()});
    EXPECT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("\"valid\":true"), std::string::npos);
}

TEST(Cli, ConfigCheckExits78NamingTheKey) {
    const auto dir = test::freshTempDir();
    std::ofstream(dir / "bad.json") << R"({"camera": {"fps": 0}})";
    auto r = test::runProgram({icewatchBin(), "config", "check", (dir / "bad.json").string()});
    EXPECT_EQ(r.status, kExitConfig);
    EXPECT_NE(r.err.find("bad.json: camera.fps: must be between"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace icewatch
