// icewatch config check: validate a configuration file the way the daemon will load it.
#include <iostream>

#include <nlohmann/json.hpp>

#include "core/config/config.hpp"
#include "tools/icewatch/command.hpp"

namespace icewatch::cli {

void addConfigCommand(CLI::App& app, const GlobalOptions& /*global*/, RunFunction& run) {
    CLI::App* config = app.add_subcommand("config", "work with configuration files");
    config->require_subcommand(1);
    CLI::App* check = config->add_subcommand("check", "validate a configuration file (exit 78 when invalid)");
    auto file = std::make_shared<std::string>();
    check->add_option("--config,config", *file, "configuration file")->required();
    check->callback([&run, file] {
        run = [file] {
            const config::Config loaded = config::loadConfig(*file);
            std::cout << nlohmann::json{{"config", *file}, {"valid", true}}.dump() << "\n";
            return 0;
        };
    });
}

}  // namespace icewatch::cli
