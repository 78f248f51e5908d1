// The configuration parser: any text gives a Config or a ConfigError (exit 78); any other
// exception, a crash or a hang is a finding.
#include <string_view>

#include "core/config/config.hpp"
#include "core/config/section.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    try {
        icewatch::config::parseConfig(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.json");
    } catch (const icewatch::config::ConfigError&) {
    }
    return 0;
}
