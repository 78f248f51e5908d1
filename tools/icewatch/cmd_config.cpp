// icewatch config check: validate a configuration file the way the daemon will load it, and the
// files it names, reporting every problem at once (a person on a tower fixes them in one go).
#include <filesystem>
#include <iostream>

#include <nlohmann/json.hpp>

#include "core/calib/stereo_calibration.hpp"
#include "core/common/error.hpp"
#include "core/config/config.hpp"
#include "tools/icewatch/command.hpp"

namespace icewatch::cli {

namespace {

namespace fs = std::filesystem;

// The files a valid configuration names: they exist and, where the daemon reads them at start,
// parse. The HTTP token file is not among them: icewatchd creates it.
void checkNamedFiles(const config::Config& c, std::vector<std::string>& problems) {
    const std::string& file = c.sourceFile;
    try {
        calib::loadCalibration(c.calibration.file);
    } catch (const std::exception& e) {  // Error, or OpenCV's on a file that is no YAML
        problems.push_back(file + ": calibration.file: " + e.what() +
                           (fs::exists(c.calibration.file) ? "" : " (make one with icewatch calibrate)"));
    }
    if (c.camera.device.starts_with("fake:")) {
        const fs::path recording = fs::path(c.camera.device.substr(5)) / "recording.json";
        if (!fs::is_regular_file(recording)) {
            problems.push_back(file + ": camera.device: " + recording.string() + ": no recording there");
        }
    }
    for (const auto& [key, path] : {std::pair{"scada.mqtt.password_file", c.scada.mqtt.passwordFile},
                                    std::pair{"scada.mqtt.ca_file", c.scada.mqtt.caFile}}) {
        if (!path.empty() && !fs::is_regular_file(path)) {
            problems.push_back(file + ": " + key + ": " + path + ": no such file");
        }
    }
}

}  // namespace

void addConfigCommand(CLI::App& app, const GlobalOptions& /*global*/, RunFunction& run) {
    CLI::App* config = app.add_subcommand("config", "work with configuration files");
    config->require_subcommand(1);
    CLI::App* check = config->add_subcommand(
        "check", "validate a configuration file and the files it names, reporting every problem (exit 78 when any)");
    auto file = std::make_shared<std::string>();
    check->add_option("--config,config", *file, "configuration file")->required();
    check->callback([&run, file] {
        run = [file] {
            config::ConfigCheck result = config::checkConfigFile(*file);
            // Only a file that could be read names files worth looking for.
            if (result.problems.empty() || fs::is_regular_file(*file)) checkNamedFiles(result.config, result.problems);
            for (const auto& problem : result.problems) std::cerr << "icewatch: " << problem << "\n";
            std::cout << nlohmann::json{{"config", *file}, {"valid", result.problems.empty()}, {"problems", result.problems}}
                             .dump()
                      << "\n";
            return result.problems.empty() ? kExitOk : static_cast<int>(kExitConfig);
        };
    });
}

}  // namespace icewatch::cli
