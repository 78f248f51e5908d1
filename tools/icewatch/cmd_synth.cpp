// icewatch synth: render a synthetic scene of known ice volume (calibration, two side-by-side
// captures, the object's outline and the truth) for the volume chain and its benchmark. A capture
// of one frame is written as before.png / after.png; a capture of several frames as a recording
// (before/, after/) in the format the camera's recorder writes, so it replays like a real burst.
#include <charconv>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <regex>

#include <nlohmann/json.hpp>

#include "core/common/error.hpp"
#include "core/synth/scene.hpp"
#include "drivers/v4l2/recording.hpp"
#include "tools/icewatch/command.hpp"
#include "tools/icewatch/terminal.hpp"

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

constexpr int kRecordingFps = 30;

// Removes the captures an earlier rendering left in dir (before.png / after.png, or the before/ and
// after/ recordings), so a scene directory never holds two captures that disagree. Only files this
// command writes are touched.
void removeOldCaptures(const std::filesystem::path& dir) {
    namespace fs = std::filesystem;
    std::error_code ec;
    for (const char* capture : {"before", "after"}) {
        fs::remove(dir / (std::string(capture) + ".png"), ec);
        const fs::path recording = dir / capture;
        if (!fs::is_directory(recording, ec)) continue;
        static const std::regex frameName(R"(\d{6}\.jpg)");
        for (const auto& entry : fs::directory_iterator(recording, ec)) {
            if (std::regex_match(entry.path().filename().string(), frameName)) fs::remove(entry.path(), ec);
        }
        fs::remove(recording / "recording.json", ec);
        fs::remove(recording, ec);  // only when now empty
    }
}

// One capture's frames as a recording, 1/30 s apart, as the camera's MJPEG stream would deliver them.
void writeRecording(const std::filesystem::path& dir, const std::vector<std::vector<uchar>>& frames, cv::Size mode) {
    v4l2::RecordingWriter writer(dir, "synth", v4l2::PixelFormat::kMjpeg, mode.width, mode.height, kRecordingFps);
    for (std::size_t k = 0; k < frames.size(); ++k) {
        const auto timestampUs = static_cast<std::int64_t>(std::llround(1e6 * static_cast<double>(k) / kRecordingFps));
        writer.add(frames[k].data(), frames[k].size(), timestampUs);
    }
    writer.finish();
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
        unsigned noiseDraw = 0;
        int jpegQuality = 90;
        int supersampling = 3;
        std::string out;
        bool truthMaps = false;
        int frames = 1;
        std::string ice = "leading-edge";
        std::string motion = "small";
        std::string background = "sky";
        std::string optics = "painted";
        double lightChange = 1.0;
        double lightTurnDeg = 0.0;
        double distanceMm = 850.0;
        double rollDeg = 0.0;
        double tiltDeg = 0.0;
        double swingDeg = 0.0;
        double cloudDrift = 0.0;
        double gloss = 0.0;
        double textureContrast = 0.0;
        double textureFeatureMm = 0.0;
        double iceWhiteness = 0.0;
        bool shadows = false;
        double tableGapMm = 0.0;
        bool iceOverEdges = false;
        double icicleLength = 1.0;
        double blurPx = 0.0;
        std::string toneCurve = "linear";
        double sunChange = 1.0;
        double sunAngleDeg = 0.0;
        bool force = false;
        bool json = false;
    };
    auto o = std::make_shared<Options>();
    cmd->add_option("--scene", o->scene, "blade or block")->check(CLI::IsMember({"blade", "block"}));
    cmd->add_option("--ice-volume-mm3", o->volumeMm3, "ice volume to render, mm3")->required();
    cmd->add_option("--seed", o->seed, "pose, motion, look (light, textures, ice appearance), rime patches and noise");
    cmd->add_option("--mode", o->mode, "side-by-side frame size, e.g. 2560x720 or 3840x1080");
    cmd->add_option("--noise", o->noise, "sensor noise sigma, grey levels");
    cmd->add_option("--noise-draw", o->noiseDraw,
                    "another draw of the sensor noise and JPEG encoding for the same scene (0: the seed's own); "
                    "everything else stays, so the noise's share of an error can be measured");
    cmd->add_option("--jpeg-quality", o->jpegQuality, "JPEG quality 1..100");
    cmd->add_option("--supersampling", o->supersampling, "samples per pixel and axis (anti-aliasing)");
    cmd->add_option("--frames", o->frames,
                    "frames per capture; more than 1 writes before/ and after/ as recordings (recording.json + "
                    "000001.jpg ...), each frame with its own noise and JPEG encoding")
        ->check(CLI::Range(1, synth::kMaxFrames));
    cmd->add_option("--ice", o->ice,
                    "the blade's ice: leading-edge (a horn along the leading edge), glaze-all (a thin translucent "
                    "layer over the whole blade), patches (opaque rime patches anywhere), bead (a narrow bead on the leading "
                    "edge, standing out of the outline), bead-glaze (the bead over a thin glaze), ridges (a few narrow, "
                    "steep ridges of runback ice along the span), shed (sheets of one thickness left after part of the ice "
                    "shed, each ending in a sharp step) or icicles (icicles hanging out of the trailing edge, far beyond "
                    "the outline, over a runback band along it)")
        ->check(CLI::IsMember({"leading-edge", "glaze-all", "patches", "bead", "bead-glaze", "ridges", "shed", "icicles"}));
    cmd->add_option("--motion", o->motion,
                    "the object's motion between the captures: none, small (up to 3 mm, 0.3°) or large (up to 15 mm, "
                    "1.5°: parked at another pitch, bent by another wind)")
        ->check(CLI::IsMember({"none", "small", "large"}));
    cmd->add_option("--background", o->background,
                    "sky (overcast) or table (the object lies on a textured tabletop and moves with it)")
        ->check(CLI::IsMember({"sky", "table"}));
    cmd->add_option("--ice-optics", o->optics,
                    "how the blade shows through thin, translucent or clear ice: painted (blended on the ice's "
                    "surface, as most renderers draw it) or refractive (where it is, under the ice, along rays the ice "
                    "bends: a clear glaze then looks raised by a quarter of its thickness)")
        ->check(CLI::IsMember({"painted", "refractive"}));
    cmd->add_option("--light-change", o->lightChange,
                    "the current capture's illumination times this, 0.2..3 (saturates at white)")
        ->check(CLI::Range(synth::kMinLightChange, synth::kMaxLightChange));
    cmd->add_option("--sun-change", o->sunChange,
                    "the current capture's direct light (the sun, a rig's lamps) times this, 0..3, the sky's light "
                    "unchanged: a surface facing the sun changes more than one facing away, the sky behind not at all")
        ->check(CLI::Range(0.0, synth::kMaxSunChange));
    cmd->add_option("--sun-angle", o->sunAngleDeg,
                    "the light's angle from the view axis, 0..80 degrees (0: the seed's, 9-44; 70: a low sun from the "
                    "side, half the blade in its own shade and long shadows)")
        ->check(CLI::Range(0.0, synth::kMaxSunAngleDeg));
    cmd->add_option("--light-turn", o->lightTurnDeg,
                    "the current capture's light direction turned by this many degrees (the sun moved across the sky "
                    "and in height: a curved surface's shading changes unevenly), 0..60")
        ->check(CLI::Range(0.0, synth::kMaxLightTurnDeg));
    cmd->add_option("--distance-mm", o->distanceMm, "camera to object, 600..1500 mm")
        ->check(CLI::Range(synth::kMinDistanceMm, synth::kMaxDistanceMm));
    cmd->add_option("--roll", o->rollDeg,
                    "the object turned about the view axis by this many degrees (a blade parked at another angle), "
                    "-180..180 (180: tip and leading edge the other way round); it must still fit in the frame")
        ->check(CLI::Range(-synth::kMaxRollDeg, synth::kMaxRollDeg));
    cmd->add_option("--tilt", o->tiltDeg,
                    "the object turned about the image's horizontal axis by this many degrees (seen from above or "
                    "below: a blade on a table looked at from an angle, its chord foreshortened), -45..45")
        ->check(CLI::Range(-synth::kMaxTiltDeg, synth::kMaxTiltDeg));
    cmd->add_option("--swing", o->swingDeg,
                    "the object turned about the image's vertical axis by this many degrees (one end nearer than the "
                    "other), -45..45; it must still fit in the frame")
        ->check(CLI::Range(-synth::kMaxTiltDeg, synth::kMaxTiltDeg));
    cmd->add_option("--clouds", o->cloudDrift,
                    "soft clouds in the sky, drifting by this share of the image's width between the captures, "
                    "0..0.5 (0: an even overcast)")
        ->check(CLI::Range(0.0, synth::kMaxCloudDrift));
    cmd->add_option("--gloss", o->gloss,
                    "highlights: the peak of the light that wet ice mirrors towards the eye, 0..1 (the blade's coat "
                    "a third of it, rime none; 0: every surface matte); each eye sees a highlight at another place")
        ->check(CLI::Range(0.0, synth::kMaxGloss));
    cmd->add_flag("--shadows", o->shadows,
                  "the sun casts shadows: the object darkens the table or the plate beside it, ice standing out "
                  "the surface behind it; shadows slide with the object and the light");
    cmd->add_option("--table-gap-mm", o->tableGapMm,
                    "on a table, the blade rests this far above it, 0..100 mm (on trestles, or a whole airfoil "
                    "on its lower surface, its edges standing off the table): the outline steps down to the table")
        ->check(CLI::Range(0.0, synth::kMaxTableGapMm));
    cmd->add_flag("--ice-over-edges", o->iceOverEdges,
                  "glaze-all grown along the surface's normals, as ice forms: it wraps the leading and trailing "
                  "edges and stands out of the outline by its thickness there, clear, what lies behind showing through");
    cmd->add_option("--icicle-length", o->icicleLength,
                    "icicles' lengths times this, 0.1..2 (1: 3 to 7 times their size, far beyond the ring the chain "
                    "watches around the outline; 0.25: stubby, as much ice within a few tens of mm)")
        ->check(CLI::Range(synth::kMinIcicleLength, synth::kMaxIcicleLength));
    cmd->add_option("--blur-px", o->blurPx,
                    "the lens's blur: a Gaussian of this sigma on each eye, 0..5 px (0: as sharp as the pixels; a "
                    "renderer's pixel filter is about 0.5, a cheap lens 1 or more)")
        ->check(CLI::Range(0.0, synth::kMaxBlurPx));
    cmd->add_option("--tone-curve", o->toneCurve,
                    "how light becomes grey levels: linear (as raw data), gamma (a power law of 1/2.2, as sRGB and a "
                    "UVC camera: a change of light scales every grey level alike, but less) or filmic (a toe, a "
                    "compressed shoulder and sRGB's gamma, as renderers and cameras' processors make pictures: a "
                    "change of light changes bright and dark surfaces unequally)")
        ->check(CLI::IsMember({"linear", "gamma", "filmic"}));
    cmd->add_option("--texture-contrast", o->textureContrast,
                    "the blade's texture amplitude, a share of its albedo, 0.005..0.3 (default: the "
                    "seed's, 0.027..0.05: a weak composite texture; 0.3 is a speckle pattern)")
        ->check(CLI::Range(synth::kMinTextureContrast, synth::kMaxTextureContrast));
    cmd->add_option("--texture-feature-mm", o->textureFeatureMm,
                    "the size of the texture's coarsest features, 0.5..50 mm (default: the seed's, 4.5..8.5)")
        ->check(CLI::Range(synth::kMinTextureFeatureMm, synth::kMaxTextureFeatureMm));
    cmd->add_option("--ice-whiteness", o->iceWhiteness,
                    "the albedo of ice thick enough to hide what is under it, 0.4..1 (default: the seed's, "
                    "0.82..0.93; grey, dirty ice lower)")
        ->check(CLI::Range(synth::kMinIceWhiteness, synth::kMaxIceWhiteness));
    cmd->add_option("--out", o->out, "scene directory to write")->required();
    addForceFlag(*cmd, o->force);
    cmd->add_flag("--json", o->json, "print what was written as one JSON object");
    cmd->add_flag("--truth-maps", o->truthMaps,
                  "also write the left eye's true disparities (truth_disparity_{before,after}.pfm) and ice thickness "
                  "(truth_ice_mm.pfm)");
    cmd->callback([&run, o] {
        run = [o] {
            if (o->scene == "block" && o->ice != "leading-edge") {
                throw Error(kExitUsage,
                            "--ice " + o->ice + ": the ice kind is the blade's; a block scene's ice is the block");
            }
            if (o->iceOverEdges && (o->scene != "blade" || o->ice != "glaze-all")) {
                throw Error(kExitUsage, "--ice-over-edges: only a glaze-all blade's ice is grown over its edges (--ice " +
                                            o->ice + ", --scene " + o->scene + ")");
            }
            if (o->icicleLength != 1.0 && (o->scene != "blade" || o->ice != "icicles")) {
                throw Error(kExitUsage, "--icicle-length: only icicles have a length (--ice " + o->ice + ", --scene " +
                                            o->scene + ")");
            }
            checkOutputDirectory(o->out, o->force, "--out");
            synth::SceneSpec spec;
            spec.kind = synth::parseSceneKind(o->scene);
            spec.iceVolumeMm3 = o->volumeMm3;
            spec.seed = o->seed;
            spec.frameSize = parseMode(o->mode);
            spec.noiseSigma = o->noise;
            spec.noiseDraw = o->noiseDraw;
            spec.jpegQuality = o->jpegQuality;
            spec.supersampling = o->supersampling;
            spec.frames = o->frames;
            spec.ice = synth::parseIceKind(o->ice);
            spec.motion = synth::parseMotionKind(o->motion);
            spec.background = synth::parseBackground(o->background);
            spec.optics = synth::parseIceOptics(o->optics);
            spec.lightChange = o->lightChange;
            spec.lightTurnDeg = o->lightTurnDeg;
            spec.distanceMm = o->distanceMm;
            spec.rollDeg = o->rollDeg;
            spec.tiltDeg = o->tiltDeg;
            spec.swingDeg = o->swingDeg;
            spec.cloudDrift = o->cloudDrift;
            spec.gloss = o->gloss;
            spec.shadows = o->shadows;
            spec.tableGapMm = o->tableGapMm;
            spec.iceOverEdges = o->iceOverEdges;
            spec.icicleLength = o->icicleLength;
            spec.blurPx = o->blurPx;
            spec.toneCurve = synth::parseToneCurve(o->toneCurve);
            spec.sunChange = o->sunChange;
            spec.sunAngleDeg = o->sunAngleDeg;
            spec.textureContrast = o->textureContrast;
            spec.textureFeatureMm = o->textureFeatureMm;
            spec.iceWhiteness = o->iceWhiteness;
            Progress progress("synth");
            progress.show("rendering " + o->mode + " x " + std::to_string(spec.frames) + " frames");
            const synth::SyntheticScene scene = synth::renderScene(spec);
            progress.show("writing " + o->out);
            removeOldCaptures(o->out);
            synth::writeScene(scene, spec, o->out, o->truthMaps);
            if (spec.frames > 1) {
                const std::filesystem::path out = o->out;
                writeRecording(out / "before", scene.beforeJpeg, spec.frameSize);
                writeRecording(out / "after", scene.afterJpeg, spec.frameSize);
            }
            progress.done();
            if (o->json) {
                std::cout << nlohmann::json{{"out", o->out}, {"scene", o->scene}, {"ice_volume_mm3", scene.iceVolumeMm3},
                                          {"frames", spec.frames}}
                                 .dump()
                          << "\n";
            } else {
                std::cout << "wrote a " << o->scene << " scene of " << scene.iceVolumeMm3 << " mm3 of ice, "
                          << spec.frames << " frame(s) per capture, to " << o->out << "\n";
            }
            return 0;
        };
    });
}

}  // namespace icewatch::cli
