// Synthetic scenes of known ice volume. Nothing public carries iced blades with measured volumes,
// so the chain is proven on renderings whose truth comes from the geometry itself.
//
// The camera is the ideal HBVCAM (calib::nominalCalibration): pinhole, 60 mm baseline, 80° HFOV,
// the object 0.85 m away and nearly fronto-parallel. Objects are triangle meshes in an object
// frame (x, y in the object's plane, h its height towards the camera), posed in the left camera
// frame; both eyes are z-buffer rasterised at `supersampling`² samples per pixel, shaded from
// procedural textures fixed to the surface, box-filtered down, given Gaussian sensor noise and
// passed through JPEG like the camera's MJPEG stream.
//
// The ice is a height field over the same triangulated planform as the clean surface, so its
// volume is exact for what is rendered: the sum over triangles of area × mean vertex thickness.
// The blade's ice amplitude is scaled so that this sum is the requested volume.
#include "core/synth/scene.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <random>

#include <nlohmann/json.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/common/error.hpp"
#include "core/common/side_by_side.hpp"
#include "core/stereo/disparity_io.hpp"
#include "core/stereo/matcher.hpp"
#include "core/synth/rasterizer.hpp"
#include "core/synth/sensor.hpp"
#include "core/synth/texture.hpp"

namespace icewatch::synth {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kMaterialBlade = 0;
constexpr int kMaterialIceBlock = 1;
constexpr int kMaterialPlate = 2;

// The seed paper's model blade.
constexpr double kBladeLengthMm = 820.0;
constexpr double kRootChordMm = 120.0;
constexpr double kTipChordMm = 32.0;
constexpr double kAirfoilThickness = 0.12;  // NACA 0012 half-thickness seen from the suction side
constexpr double kPitchAxisChord = 0.3;

// Table 5's block: a fixed footprint, the height makes the volume.
constexpr double kBlockLengthMm = 100.0;
constexpr double kBlockWidthMm = 80.0;
constexpr double kPlateLengthMm = 420.0;
constexpr double kPlateWidthMm = 320.0;
constexpr double kPlateRoiInsetMm = 25.0;

struct Pose {
    cv::Matx33d rotation;
    cv::Vec3d translation;
    cv::Vec3d toCamera(double x, double y, double h) const { return rotation * cv::Vec3d(x, y, -h) + translation; }
};

cv::Matx33d rotationFromDegrees(const cv::Vec3d& deg) {
    cv::Mat r;
    cv::Rodrigues(cv::Vec3d(deg[0], deg[1], deg[2]) * (kPi / 180.0), r);
    return cv::Matx33d(r);
}

double smoothstep(double e0, double e1, double x) {
    const double t = std::clamp((x - e0) / (e1 - e0), 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}

// A surface sampled on a (nu+1) × (nv+1) grid in its object frame, triangulated two per cell.
struct GridSurface {
    int nu = 0, nv = 0;
    std::vector<cv::Vec3d> local;  // x, y, h
    std::vector<float> ice;        // ice thickness carried at each vertex, mm
    std::size_t index(int i, int j) const { return static_cast<std::size_t>(j) * (nu + 1) + i; }
};

std::vector<std::array<int, 3>> gridTriangles(int nu, int nv) {
    std::vector<std::array<int, 3>> triangles;
    triangles.reserve(static_cast<std::size_t>(nu) * nv * 2);
    for (int j = 0; j < nv; ++j) {
        for (int i = 0; i < nu; ++i) {
            const int a = j * (nu + 1) + i, b = a + 1, c = a + nu + 1, d = c + 1;
            triangles.push_back({a, b, d});
            triangles.push_back({a, d, c});
        }
    }
    return triangles;
}

// Ice volume of a grid surface: planform area of each triangle (in the object's x-y plane) times
// its mean vertex thickness. Exact for the piecewise-linear surface that is rendered.
double iceVolumeMm3(const GridSurface& s) {
    double volume = 0.0;
    for (const auto& t : gridTriangles(s.nu, s.nv)) {
        const cv::Vec3d& p0 = s.local[static_cast<std::size_t>(t[0])];
        const cv::Vec3d& p1 = s.local[static_cast<std::size_t>(t[1])];
        const cv::Vec3d& p2 = s.local[static_cast<std::size_t>(t[2])];
        const double area = 0.5 * std::abs((p1[0] - p0[0]) * (p2[1] - p0[1]) - (p2[0] - p0[0]) * (p1[1] - p0[1]));
        volume += area * (s.ice[static_cast<std::size_t>(t[0])] + s.ice[static_cast<std::size_t>(t[1])] +
                          s.ice[static_cast<std::size_t>(t[2])]) /
                  3.0;
    }
    return volume;
}

// The blade planform and its ice shape for amplitude 1 (mm of leading-edge ice at full span
// weight). Ice grows towards the tip (accretion scales with the local speed) and leaves the root
// and the rear of the chord clean: leading-edge accretion decaying over a quarter of the chord
// plus a thin glaze running back to about half chord.
GridSurface bladeSurface(std::uint32_t seed) {
    GridSurface s;
    s.nu = 410;
    s.nv = 96;
    s.local.resize(static_cast<std::size_t>(s.nu + 1) * (s.nv + 1));
    s.ice.resize(s.local.size());
    for (int j = 0; j <= s.nv; ++j) {
        const double chordPos = 0.5 * (1.0 - std::cos(kPi * j / s.nv));  // dense at both edges
        for (int i = 0; i <= s.nu; ++i) {
            const double spanPos = static_cast<double>(i) / s.nu;
            const double x = (spanPos - 0.5) * kBladeLengthMm;
            const double chord = kRootChordMm + (kTipChordMm - kRootChordMm) * spanPos;
            const double y = (chordPos - kPitchAxisChord) * chord;
            const double c = chordPos;
            const double h = 5.0 * kAirfoilThickness * chord *
                             (0.2969 * std::sqrt(c) - 0.1260 * c - 0.3516 * c * c + 0.2843 * c * c * c -
                              0.1036 * c * c * c * c);
            const double spanWeight = smoothstep(0.2, 0.5, spanPos) * (0.8 + 0.4 * spanPos);
            const double shape = std::exp(-c / 0.25) * (1.0 - smoothstep(0.4, 0.6, c)) + 0.3 * (1.0 - smoothstep(0.3, 0.55, c));
            const double roughness = 1.0 + 0.2 * fractalNoise(x, y, 15.0, 2, seed + 500);
            s.local[s.index(i, j)] = {x, y, std::max(0.0, h)};
            s.ice[s.index(i, j)] = static_cast<float>(spanWeight * shape * roughness);
        }
    }
    return s;
}

std::vector<cv::Vec3d> gridNormals(const GridSurface& s, const std::vector<cv::Vec3d>& camera) {
    std::vector<cv::Vec3d> normals(camera.size());
    for (int j = 0; j <= s.nv; ++j) {
        for (int i = 0; i <= s.nu; ++i) {
            const cv::Vec3d du = camera[s.index(std::min(i + 1, s.nu), j)] - camera[s.index(std::max(i - 1, 0), j)];
            const cv::Vec3d dv = camera[s.index(i, std::min(j + 1, s.nv))] - camera[s.index(i, std::max(j - 1, 0))];
            cv::Vec3d n = du.cross(dv);
            const double len = cv::norm(n);
            n = len > 0 ? n / len : cv::Vec3d(0, 0, -1);
            normals[s.index(i, j)] = n[2] > 0 ? -n : n;  // facing the camera
        }
    }
    return normals;
}

float lambert(const cv::Vec3d& normal) {
    static const cv::Vec3d light = cv::normalize(cv::Vec3d(-0.3, -0.5, -1.0));
    return static_cast<float>(0.55 + 0.45 * std::max(0.0, normal.dot(light)));
}

// The blade as rendered: clean (iceScale 0) or iced, posed in the camera frame.
Mesh bladeMesh(const GridSurface& s, double iceScale, const Pose& pose) {
    Mesh mesh;
    mesh.material = kMaterialBlade;
    mesh.vertices.resize(s.local.size());
    for (std::size_t k = 0; k < s.local.size(); ++k) {
        const cv::Vec3d& p = s.local[k];
        mesh.vertices[k] = pose.toCamera(p[0], p[1], p[2] + iceScale * s.ice[k]);
    }
    const auto normals = gridNormals(s, mesh.vertices);
    mesh.attributes.resize(s.local.size());
    for (std::size_t k = 0; k < s.local.size(); ++k) {
        mesh.attributes[k] = {static_cast<float>(s.local[k][0]), static_cast<float>(s.local[k][1]), lambert(normals[k]),
                              static_cast<float>(iceScale * s.ice[k])};
    }
    mesh.triangles = gridTriangles(s.nu, s.nv);
    return mesh;
}

// A flat rectangle in the object plane at height h, subdivided so that no triangle is huge.
void addQuad(Mesh& mesh, const Pose& pose, const cv::Vec3d& origin, const cv::Vec3d& edgeU, const cv::Vec3d& edgeV,
             int divisions) {
    const int base = static_cast<int>(mesh.vertices.size());
    const cv::Vec3d a = pose.toCamera(origin[0], origin[1], origin[2]);
    const cv::Vec3d b = pose.toCamera(origin[0] + edgeU[0], origin[1] + edgeU[1], origin[2] + edgeU[2]);
    const cv::Vec3d c = pose.toCamera(origin[0] + edgeV[0], origin[1] + edgeV[1], origin[2] + edgeV[2]);
    cv::Vec3d n = (b - a).cross(c - a);
    n = cv::normalize(n);
    if (n[2] > 0) n = -n;
    const float shade = lambert(n);
    for (int j = 0; j <= divisions; ++j) {
        for (int i = 0; i <= divisions; ++i) {
            const double fu = static_cast<double>(i) / divisions, fv = static_cast<double>(j) / divisions;
            const cv::Vec3d local = origin + fu * edgeU + fv * edgeV;
            mesh.vertices.push_back(pose.toCamera(local[0], local[1], local[2]));
            // Texture coordinates: the two in-plane coordinates that vary on this face.
            const double ta = std::abs(edgeU[0]) + std::abs(edgeV[0]) > 0 ? local[0] : local[1];
            const double tb = std::abs(edgeU[1]) + std::abs(edgeV[1]) > 0 && ta != local[1] ? local[1] : local[2];
            // The extra attribute: the height above the object plane, which for the ice block is
            // its thickness (the truth maps' ice; the plate's is 0).
            const float height = mesh.material == kMaterialIceBlock ? static_cast<float>(local[2]) : 0.0f;
            mesh.attributes.push_back({static_cast<float>(ta), static_cast<float>(tb), shade, height});
        }
    }
    for (const auto& t : gridTriangles(divisions, divisions)) {
        mesh.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
    }
}

std::vector<Mesh> blockMeshes(double blockHeightMm, const Pose& pose) {
    Mesh plate;
    plate.material = kMaterialPlate;
    addQuad(plate, pose, {-kPlateLengthMm / 2, -kPlateWidthMm / 2, 0}, {kPlateLengthMm, 0, 0}, {0, kPlateWidthMm, 0},
            16);
    std::vector<Mesh> meshes{plate};
    if (blockHeightMm > 0) {
        Mesh block;
        block.material = kMaterialIceBlock;
        const double x0 = -kBlockLengthMm / 2 + 15.0, y0 = -kBlockWidthMm / 2 - 10.0;
        const double x1 = x0 + kBlockLengthMm, y1 = y0 + kBlockWidthMm, h = blockHeightMm;
        addQuad(block, pose, {x0, y0, h}, {kBlockLengthMm, 0, 0}, {0, kBlockWidthMm, 0}, 8);
        addQuad(block, pose, {x0, y0, 0}, {kBlockLengthMm, 0, 0}, {0, 0, h}, 8);
        addQuad(block, pose, {x0, y1, 0}, {kBlockLengthMm, 0, 0}, {0, 0, h}, 8);
        addQuad(block, pose, {x0, y0, 0}, {0, kBlockWidthMm, 0}, {0, 0, h}, 8);
        addQuad(block, pose, {x1, y0, 0}, {0, kBlockWidthMm, 0}, {0, 0, h}, 8);
        meshes.push_back(block);
    }
    return meshes;
}

// Grey level (0..1) of one sample from its material and surface coordinates.
float shadeSample(int material, const cv::Vec4f& a, float skyY, std::uint32_t seed) {
    switch (material) {
        case kMaterialBlade: {
            // Composite: a weak, smooth texture (the hard case for a matcher).
            float albedo = 0.62f + 0.035f * fractalNoise(a[0], a[1], 6.0, 4, seed) +
                           0.015f * fractalNoise(a[0], a[1], 1.2, 2, seed + 7);
            if (a[3] > 0.0f) {
                // Ice: white, translucent where thin, with its own faint texture.
                const float opacity = 1.0f - std::exp(-a[3] / 1.5f);
                const float ice = 0.88f + 0.03f * fractalNoise(a[0], a[1], 3.0, 3, seed + 100);
                albedo += (ice - albedo) * opacity;
            }
            return albedo * a[2];
        }
        case kMaterialIceBlock:
            return (0.86f + 0.04f * fractalNoise(a[0], a[1], 4.0, 4, seed + 200)) * a[2];
        case kMaterialPlate:
            return (0.45f + 0.12f * fractalNoise(a[0], a[1], 8.0, 5, seed + 300)) * a[2];
        default:
            // Overcast sky: bright, almost featureless.
            return 0.80f + 0.05f * skyY;
    }
}

// What the left eye sees of the geometry, per pixel: true disparity and ice thickness.
struct EyeTruth {
    cv::Mat disparity;
    cv::Mat iceMm;
};

// Averages over each pixel's samples; stereo::kInvalidDisparity where any sample misses the object
// (sky, or a pixel astride the outline, whose depth is mixed).
EyeTruth truthFromSamples(const SampleBuffer& samples, int supersampling, cv::Size eye, double focalPx,
                          double baselineMm) {
    EyeTruth truth{cv::Mat(eye, CV_32F), cv::Mat(eye, CV_32F)};
    const int s = supersampling;
    for (int y = 0; y < eye.height; ++y)
        for (int x = 0; x < eye.width; ++x) {
            double inverseDepth = 0, ice = 0;
            bool whole = true;
            for (int j = 0; j < s && whole; ++j)
                for (int i = 0; i < s; ++i) {
                    const int sy = y * s + j, sx = x * s + i;
                    if (samples.material.at<int>(sy, sx) < 0) {
                        whole = false;
                        break;
                    }
                    inverseDepth += samples.inverseDepth.at<float>(sy, sx);
                    ice += samples.attributes.at<cv::Vec4f>(sy, sx)[3];
                }
            const float none = stereo::kInvalidDisparity;
            truth.disparity.at<float>(y, x) = whole ? static_cast<float>(focalPx * baselineMm * inverseDepth / (s * s)) : none;
            truth.iceMm.at<float>(y, x) = whole ? static_cast<float>(ice / (s * s)) : none;
        }
    return truth;
}

cv::Mat renderEye(const std::vector<Mesh>& meshes, const calib::StereoCalibration& calibration, double centreXMm,
                  int supersampling, std::uint32_t seed, double truthBaselineMm = 0, EyeTruth* truth = nullptr) {
    const cv::Size eye = calibration.imageSize;
    PinholeView view;
    view.fPx = calibration.M1.at<double>(0, 0) * supersampling;
    view.cxPx = (calibration.M1.at<double>(0, 2) + 0.5) * supersampling - 0.5;
    view.cyPx = (calibration.M1.at<double>(1, 2) + 0.5) * supersampling - 0.5;
    view.centreXMm = centreXMm;
    view.size = {eye.width * supersampling, eye.height * supersampling};
    const SampleBuffer samples = rasterize(meshes, view);
    cv::Mat fine(view.size, CV_32F);
    // Rows in fixed stripes: each sample is a pure function of its inputs, so the result does not
    // depend on the thread count.
    cv::parallel_for_(cv::Range(0, view.size.height), [&](const cv::Range& rows) {
        for (int y = rows.start; y < rows.end; ++y) {
            const auto* material = samples.material.ptr<int>(y);
            const auto* attributes = samples.attributes.ptr<cv::Vec4f>(y);
            auto* out = fine.ptr<float>(y);
            const float skyY = 1.0f - static_cast<float>(y) / view.size.height;
            for (int x = 0; x < view.size.width; ++x) {
                out[x] = shadeSample(material[x], attributes[x], skyY, seed);
            }
        }
    });
    cv::Mat pixels;
    cv::resize(fine, pixels, eye, 0, 0, cv::INTER_AREA);
    if (truth) *truth = truthFromSamples(samples, supersampling, eye, calibration.M1.at<double>(0, 0), truthBaselineMm);
    return pixels;
}

cv::Point2d projectLeft(const calib::StereoCalibration& c, const cv::Vec3d& p) {
    return {c.M1.at<double>(0, 0) * p[0] / p[2] + c.M1.at<double>(0, 2),
            c.M1.at<double>(1, 1) * p[1] / p[2] + c.M1.at<double>(1, 2)};
}

void writeImage(const std::filesystem::path& path, const cv::Mat& image) {
    bool written = false;
    try {
        written = cv::imwrite(path.string(), image);
    } catch (const cv::Exception&) {
        written = false;
    }
    if (!written) {
        throw Error(kExitCantCreate, path.string() + ": cannot write the image");
    }
}

void checkSpec(const SceneSpec& spec) {
    if (spec.frameSize.width < 64 || spec.frameSize.height < 32 || spec.frameSize.width % 2 != 0) {
        throw InvalidInput("synthetic scene: frame size must be even in width and at least 64x32");
    }
    if (!(spec.iceVolumeMm3 >= 0) || spec.iceVolumeMm3 > 5e6) {
        throw InvalidInput("synthetic scene: ice volume must be between 0 and 5e6 mm3");
    }
    if (spec.noiseSigma < 0 || spec.noiseSigma > 50) {
        throw InvalidInput("synthetic scene: noise sigma must be between 0 and 50 grey levels");
    }
    if (spec.jpegQuality < 1 || spec.jpegQuality > 100) {
        throw InvalidInput("synthetic scene: JPEG quality must be between 1 and 100");
    }
    if (spec.supersampling < 1 || spec.supersampling > 8) {
        throw InvalidInput("synthetic scene: supersampling must be between 1 and 8");
    }
    if (spec.frames < 1 || spec.frames > kMaxFrames) {
        throw InvalidInput("synthetic scene: frames per capture must be between 1 and " + std::to_string(kMaxFrames));
    }
    if (spec.kind == SceneKind::Block && spec.iceVolumeMm3 / (kBlockLengthMm * kBlockWidthMm) > 200.0) {
        throw InvalidInput("synthetic scene: a block of this volume would be taller than 200 mm");
    }
}

}  // namespace

SceneKind parseSceneKind(std::string_view name) {
    if (name == "blade") return SceneKind::Blade;
    if (name == "block") return SceneKind::Block;
    throw InvalidInput("unknown scene \"" + std::string(name) + "\" (blade, block)");
}

SyntheticScene renderScene(const SceneSpec& spec) {
    checkSpec(spec);
    std::mt19937 random(spec.seed);
    auto uniform = [&random](double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(random); };

    SyntheticScene scene;
    const cv::Size eye{spec.frameSize.width / 2, spec.frameSize.height};
    scene.calibration = calib::nominalCalibration(eye, spec.horizontalFovDeg, spec.baselineMm);

    // Nearly fronto-parallel, tilted by a few degrees so the surface spans a range of disparities.
    const bool blade = spec.kind == SceneKind::Blade;
    Pose before{rotationFromDegrees({uniform(-3, 3), uniform(2, 5), uniform(-2, 2)}),
                {uniform(-10, 10), uniform(-10, 10), spec.distanceMm}};
    const double maxShiftMm = blade ? 3.0 : 1.0, maxTurnDeg = blade ? 0.3 : 0.1;
    scene.motion.rotationDeg = {uniform(-maxTurnDeg, maxTurnDeg), uniform(-maxTurnDeg, maxTurnDeg),
                                uniform(-maxTurnDeg, maxTurnDeg)};
    scene.motion.translationMm = {uniform(-maxShiftMm, maxShiftMm), uniform(-maxShiftMm, maxShiftMm),
                                  uniform(-maxShiftMm, maxShiftMm)};
    Pose after{rotationFromDegrees(scene.motion.rotationDeg) * before.rotation,
               before.translation + scene.motion.translationMm};

    std::vector<Mesh> beforeMeshes, afterMeshes;
    if (blade) {
        GridSurface surface = bladeSurface(spec.seed);
        const double unitVolume = iceVolumeMm3(surface);
        const double scale = spec.iceVolumeMm3 / unitVolume;
        for (float& t : surface.ice) t = static_cast<float>(t * scale);
        scene.iceVolumeMm3 = iceVolumeMm3(surface);
        scene.maxIceThicknessMm = *std::max_element(surface.ice.begin(), surface.ice.end());
        beforeMeshes.push_back(bladeMesh(surface, 0.0, before));
        afterMeshes.push_back(bladeMesh(surface, 1.0, after));
        for (int i = 0; i <= surface.nu; i += 10) {  // leading edge, root to tip
            scene.roi.push_back(projectLeft(scene.calibration, before.toCamera(surface.local[surface.index(i, 0)][0],
                                                                               surface.local[surface.index(i, 0)][1], 0)));
        }
        for (int i = surface.nu; i >= 0; i -= 10) {  // trailing edge, tip to root
            const cv::Vec3d& p = surface.local[surface.index(i, surface.nv)];
            scene.roi.push_back(projectLeft(scene.calibration, before.toCamera(p[0], p[1], 0)));
        }
    } else {
        const double heightMm = spec.iceVolumeMm3 / (kBlockLengthMm * kBlockWidthMm);
        scene.iceVolumeMm3 = heightMm * kBlockLengthMm * kBlockWidthMm;
        scene.maxIceThicknessMm = heightMm;
        beforeMeshes = blockMeshes(0.0, before);
        afterMeshes = blockMeshes(heightMm, after);
        const double hx = kPlateLengthMm / 2 - kPlateRoiInsetMm, hy = kPlateWidthMm / 2 - kPlateRoiInsetMm;
        for (const auto& corner : {cv::Vec2d(-hx, -hy), cv::Vec2d(hx, -hy), cv::Vec2d(hx, hy), cv::Vec2d(-hx, hy)}) {
            scene.roi.push_back(projectLeft(scene.calibration, before.toCamera(corner[0], corner[1], 0)));
        }
    }

    const double baseline = spec.baselineMm;
    EyeTruth beforeTruth, afterTruth;
    auto light = [&](const std::vector<Mesh>& meshes, EyeTruth& truth) {
        const cv::Mat left = renderEye(meshes, scene.calibration, 0.0, spec.supersampling, spec.seed, baseline, &truth);
        const cv::Mat right = renderEye(meshes, scene.calibration, baseline, spec.supersampling, spec.seed);
        return joinSideBySide(left, right);
    };
    auto noiseSeeds = [&] {
        std::vector<std::uint32_t> seeds(static_cast<std::size_t>(spec.frames));
        for (auto& s : seeds) s = static_cast<std::uint32_t>(random());
        return seeds;
    };
    const Exposure exposure{1.0, spec.noiseSigma, spec.jpegQuality};
    scene.beforeJpeg = exposeFrames(light(beforeMeshes, beforeTruth), exposure, noiseSeeds());
    scene.afterJpeg = exposeFrames(light(afterMeshes, afterTruth), exposure, noiseSeeds());
    scene.before = cv::imdecode(scene.beforeJpeg.front(), cv::IMREAD_COLOR);
    scene.after = cv::imdecode(scene.afterJpeg.front(), cv::IMREAD_COLOR);
    scene.beforeDisparity = beforeTruth.disparity;
    scene.afterDisparity = afterTruth.disparity;
    scene.afterIceMm = afterTruth.iceMm;
    return scene;
}

void writeScene(const SyntheticScene& scene, const SceneSpec& spec, const std::filesystem::path& dir, bool truthMaps) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) {
        throw Error(kExitCantCreate, dir.string() + ": cannot create the scene directory (" + ec.message() + ")");
    }
    calib::saveCalibration(dir / "calibration.yaml", scene.calibration);
    if (scene.beforeJpeg.size() <= 1 && scene.afterJpeg.size() <= 1) {
        writeImage(dir / "before.png", scene.before);
        writeImage(dir / "after.png", scene.after);
    }
    auto writeJson = [&dir](const std::string& name, const nlohmann::json& json) {
        const auto path = dir / name;
        std::ofstream out(path);
        out << json.dump(2) << "\n";
        if (!out) {
            throw Error(kExitCantCreate, path.string() + ": cannot write");
        }
    };
    if (truthMaps) {
        stereo::writePfm(dir / "truth_disparity_before.pfm", scene.beforeDisparity);
        stereo::writePfm(dir / "truth_disparity_after.pfm", scene.afterDisparity);
        stereo::writePfm(dir / "truth_ice_mm.pfm", scene.afterIceMm);
    }
    nlohmann::json polygon = nlohmann::json::array();
    for (const auto& p : scene.roi) polygon.push_back({p.x, p.y});
    writeJson("roi.json", {{"eye", "left"}, {"polygon", polygon}});
    writeJson("truth.json", {{"scene", spec.kind == SceneKind::Blade ? "blade" : "block"},
                             {"ice_volume_mm3", scene.iceVolumeMm3},
                             {"max_ice_thickness_mm", scene.maxIceThicknessMm},
                             {"seed", spec.seed},
                             {"mode", std::to_string(spec.frameSize.width) + "x" + std::to_string(spec.frameSize.height)},
                             {"noise_sigma", spec.noiseSigma},
                             {"jpeg_quality", spec.jpegQuality},
                             {"frames", spec.frames},
                             {"motion_rotation_deg", {scene.motion.rotationDeg[0], scene.motion.rotationDeg[1],
                                                      scene.motion.rotationDeg[2]}},
                             {"motion_translation_mm", {scene.motion.translationMm[0], scene.motion.translationMm[1],
                                                        scene.motion.translationMm[2]}}});
}

}  // namespace icewatch::synth
