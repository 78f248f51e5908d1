// icewatch synth: render a synthetic scene of known ice volume (calibration, two side-by-side
// captures, the object's outline and the truth) for the volume chain and its benchmark.
#include <iostream>
#include <charconv>

#include <nlohmann/json.hpp>

#include "core/common/error.hpp"
#include "core/synth/scene.hpp"
#include "tools/icewatch/command.hpp"

namespace icewatch::cli {

namespace {

cv::Size parseMode(const std::string& mode) {
    // WIDTHxHEIGHT, both plain decimal numbers.
    const auto x = mode.find('x');
    int width = 0, height = 0;
    const char* end = mode.data() + mode.size();
    const bool ok = x != std::string::npos &&
                    std::from_chars(mode.data(), mode.data() + x, width).ptr == mode.data() + x &&
                    std::from_chars(mode.data() + x + 1, end, height).ptr == end && width > 0 && height > 0;
    if (!ok) {
        throw Error(kExitUsage, "--mode must look like 2560x720, got \"" + mode + "\"");
    }
    return {width, height};
}

}  // namespace

void addSynthCommand(CLI::App& app, const GlobalOptions& /*global*/, RunFunction& run) {
    CLI::App* cmd = app.add_subcommand("synth", "render a synthetic stereo scene with a known ice volume");
    struct Options {
        std::string scene = "blade";
        double volumeMm3 = 0;
        unsigned seed = 1;
        std::string mode = "2560x720";
        double noise = 1.5;
        int jpegQuality = 90;
        int supersampling = 3;
        std::string out;
        bool truthMaps = false;
    };
    auto o = std::make_shared<Options>();
    cmd->add_option("--scene", o->scene, "blade or block")->check(CLI::IsMember({"blade", "block"}));
    cmd->add_option("--ice-volume-mm3", o->volumeMm3, "ice volume to render, mm3")->required();
    cmd->add_option("--seed", o->seed, "texture, pose and noise seed");
    cmd->add_option("--mode", o->mode, "side-by-side frame size, e.g. 2560x720 or 3840x1080");
    cmd->add_option("--noise", o->noise, "sensor noise sigma, grey levels");
    cmd->add_option("--jpeg-quality", o->jpegQuality, "JPEG quality 1..100");
    cmd->add_option("--supersampling", o->supersampling, "samples per pixel and axis (anti-aliasing)");
    cmd->add_option("--out", o->out, "scene directory to write")->required();
    cmd->add_flag("--truth-maps", o->truthMaps,
                  "also write the left eye's true disparities (truth_disparity_{before,after}.pfm) and ice thickness "
                  "(truth_ice_mm.pfm)");
    cmd->callback([&run, o] {
        run = [o] {
            synth::SceneSpec spec;
            spec.kind = synth::parseSceneKind(o->scene);
            spec.iceVolumeMm3 = o->volumeMm3;
            spec.seed = o->seed;
            spec.frameSize = parseMode(o->mode);
            spec.noiseSigma = o->noise;
            spec.jpegQuality = o->jpegQuality;
            spec.supersampling = o->supersampling;
            const synth::SyntheticScene scene = synth::renderScene(spec);
            synth::writeScene(scene, spec, o->out, o->truthMaps);
            std::cout << nlohmann::json{{"out", o->out}, {"scene", o->scene}, {"ice_volume_mm3", scene.iceVolumeMm3}}.dump()
                      << "\n";
            return 0;
        };
    });
}

}  // namespace icewatch::cli
