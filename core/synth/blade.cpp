// The blade and its ice. The ice is a height field over the same triangulated planform as the
// clean surface, so its volume is exact for what is rendered (geometry.hpp: iceVolumeMm3). Three
// kinds of ice, each as it forms on a parked blade:
//   leading-edge  accretion decaying over a quarter of the chord plus a thin glaze running back to
//                 about half chord, growing towards the tip (accretion scales with the local
//                 speed) and leaving the root clean;
//   glaze-all     a thin layer over the whole visible surface, trailing edge, root and tip
//                 included, somewhat thicker towards the leading edge and the tip; grown along
//                 the normals (SceneSpec::iceOverEdges) it also wraps both edges (glazeEdge);
//   patches       a few soft-edged, rough rime patches anywhere on the blade, placed by the seed;
//   bead          a bead right on the leading edge, about as high as it is wide (a few mm across
//                 for a little ice, a few cm for much; its proportions by the seed), which is the
//                 blade's outline as the camera sees it: it rises over the suction side and stands
//                 out in front of the clean outline (beadFront), leaving the root clean;
//   bead-glaze    the same bead over a thin glaze across the whole visible surface;
//   ridges        two to four narrow ridges along the span behind the leading edge, where water ran
//                 back and froze: steep-sided, one to five times as wide as high, a few mm high for
//                 a little ice and a couple of cm for much (their proportions by the seed), each
//                 starting and ending somewhere along the span and wandering a little across the
//                 chord. As narrow as the matcher's window, with clean surface right beside them.
//   shed          what is left after part of the ice shed: a few sheets of one thickness anywhere
//                 on the blade, broken off along jagged lines, so that each ends in a sharp step
//                 of its full thickness (the rime patches end in slopes tens of mm long).
//   icicles       icicles hanging out of the trailing edge (icicleFront), far beyond the outline,
//                 over a runback band along the edge they grew from: the ice that matters lies
//                 where no surface was before, against the background.
#include "core/synth/blade.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include "core/synth/texture.hpp"

namespace icewatch::synth {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kBladeLengthMm = 820.0;
constexpr double kRootChordMm = 120.0;
constexpr double kTipChordMm = 32.0;
constexpr double kAirfoilThickness = 0.12;  // NACA 0012 half-thickness seen from the suction side
constexpr double kPitchAxisChord = 0.3;
constexpr double kBeadGlazeMm = 0.6;  // the glaze under a bead, mm (more towards the tip)

double smoothstep(double e0, double e1, double x) {
    const double t = std::clamp((x - e0) / (e1 - e0), 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}

// A rime patch: an ellipse in (span mm, chord fraction), so that it narrows with the chord and
// stays on the blade.
struct Patch {
    double centreXMm, centreChord, radiusXMm, radiusChord, height;

    // A point's squared distance from the centre, in radii: 1 on the ellipse.
    double distance2(double xMm, double chord) const {
        const double dx = (xMm - centreXMm) / radiusXMm, dc = (chord - centreChord) / radiusChord;
        return dx * dx + dc * dc;
    }
};

// The bead's shape: how far it reaches over the suction side (mm, the same along the span, so it
// is narrow against the root's chord and broad at the tip), how far in front of the leading edge
// and how high it stands (mm). A bead is about as high as it is wide: its size follows how much
// ice there is (bladeGeometry picks the reach that carries the requested volume), its proportions
// the seed.
struct Bead {
    double overMm, frontMm, heightMm;
};

Bead drawBead(std::uint32_t seed, double overMm) {
    std::mt19937 random(seed ^ 0x42656164u);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const double front = 0.4 + 0.6 * unit(random);
    const double aspect = 0.4 + 0.5 * unit(random);
    return {overMm, overMm * front, overMm * aspect};
}

// Across the bead (0 on the leading edge, 1 at its reach): rounded, meeting the surface at a slant.
double beadProfile(double t) { return t < 1.0 ? 1.0 - t * t : 0.0; }

// Along the span: from nothing at the root to the most towards the tip, uneven as real accretion.
double beadAlongSpan(double spanPos, double x, double y, std::uint32_t seed) {
    return smoothstep(0.15, 0.4, spanPos) * (0.8 + 0.4 * spanPos) *
           (1.0 + 0.15 * fractalNoise(x, y, 40.0, 2, seed + 700));
}

// A runback ridge: where it runs across the chord (fraction), how wide and high it is for a size of
// 1 mm, and the part of the span it covers.
struct Ridge {
    double chord, halfWidth, height, spanFrom, spanTo, wavePhase;
};

std::vector<Ridge> drawRidges(std::uint32_t seed) {
    std::mt19937 random(seed ^ 0x52696467u);
    auto uniform = [&random](double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(random); };
    std::vector<Ridge> ridges(static_cast<std::size_t>(2 + random() % 3));
    for (Ridge& r : ridges) {
        r = {uniform(0.12, 0.6), uniform(0.6, 1.2), uniform(0.5, 1.0), uniform(0.05, 0.4), uniform(0.6, 0.98),
             uniform(0.0, 2.0 * kPi)};
    }
    return ridges;
}

// An icicle: where it hangs along the span (0 root .. 1 tip), its root's radius and its length for
// a size of 1 mm.
struct Icicle {
    double spanPos, rootRadius, length;
};

std::vector<Icicle> drawIcicles(std::uint32_t seed) {
    std::mt19937 random(seed ^ 0x49636963u);
    auto uniform = [&random](double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(random); };
    std::vector<Icicle> icicles(static_cast<std::size_t>(5 + random() % 6));
    for (Icicle& i : icicles) i = {uniform(0.25, 0.95), uniform(0.4, 0.8), uniform(3.0, 7.0)};
    return icicles;
}

// How much of the trailing edge the icicles hang from (the runback band's extent along the span).
double icicleSpan(const std::vector<Icicle>& icicles, double spanPos) {
    double lo = 1.0, hi = 0.0;
    for (const Icicle& i : icicles) {
        lo = std::min(lo, i.spanPos);
        hi = std::max(hi, i.spanPos);
    }
    return smoothstep(lo - 0.08, lo - 0.02, spanPos) * (1.0 - smoothstep(hi + 0.02, hi + 0.08, spanPos));
}

std::vector<Patch> drawPatches(std::uint32_t seed) {
    std::mt19937 random(seed ^ 0x50617463u);
    auto uniform = [&random](double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(random); };
    std::vector<Patch> patches(static_cast<std::size_t>(4 + random() % 4));
    for (Patch& p : patches) {
        p = {(uniform(0.06, 0.94) - 0.5) * kBladeLengthMm, uniform(0.32, 0.68), uniform(50, 110), uniform(0.2, 0.3),
             uniform(0.6, 1.4)};
    }
    return patches;
}

// Ice thickness for amplitude 1 at span position spanPos (0 root .. 1 tip), chord position c
// (0 leading edge .. 1 trailing edge), planform point (x, y).
class IceShape {
public:
    IceShape(IceKind kind, std::uint32_t seed, double beadOverMm)
        : kind_(kind), seed_(seed), sizeMm_(beadOverMm), bead_(drawBead(seed, beadOverMm)) {
        if (kind == IceKind::Patches) patches_ = drawPatches(seed);
        if (kind == IceKind::Ridges) ridges_ = drawRidges(seed);
        if (kind == IceKind::Shed) patches_ = drawPatches(seed ^ 0x53686564u);
        if (kind == IceKind::Icicles) icicles_ = drawIcicles(seed);
    }

    // chordMm: the local chord, so that the bead keeps its width in millimetres.
    double operator()(double spanPos, double c, double chordMm, double x, double y) const {
        switch (kind_) {
            case IceKind::Bead:
            case IceKind::BeadGlaze: {
                const double bead = bead_.heightMm * beadAlongSpan(spanPos, x, -kPitchAxisChord * chordMm, seed_) *
                                    beadProfile(c * chordMm / bead_.overMm);
                const double glaze = kind_ == IceKind::BeadGlaze ? kBeadGlazeMm * (0.7 + 0.6 * spanPos) : 0.0;
                return bead + glaze;
            }
            case IceKind::LeadingEdge: {
                const double spanWeight = smoothstep(0.2, 0.5, spanPos) * (0.8 + 0.4 * spanPos);
                const double shape =
                    std::exp(-c / 0.25) * (1.0 - smoothstep(0.4, 0.6, c)) + 0.3 * (1.0 - smoothstep(0.3, 0.55, c));
                return spanWeight * shape * (1.0 + 0.2 * fractalNoise(x, y, 15.0, 2, seed_ + 500));
            }
            case IceKind::GlazeAll: {
                const double towardsEdgeAndTip = (1.0 + 1.2 * std::exp(-c / 0.15)) * (0.7 + 0.6 * spanPos);
                return towardsEdgeAndTip * (1.0 + 0.1 * fractalNoise(x, y, 20.0, 2, seed_ + 600));
            }
            case IceKind::Patches: {
                double thickness = 0.0;
                for (const Patch& p : patches_) {
                    const double d2 = p.distance2(x, c);
                    // Flat-topped with a soft edge over the outer 40 % of the radius.
                    if (d2 < 1.0) thickness = std::max(thickness, p.height * (1.0 - smoothstep(0.6, 1.0, std::sqrt(d2))));
                }
                // Rime is rough: its surface varies by a third on a scale of millimetres.
                return thickness * std::max(0.0, 1.0 + 0.35 * fractalNoise(x, y, 6.0, 3, seed_ + 800));
            }
            case IceKind::Shed: {
                for (const Patch& p : patches_) {
                    // Broken off along a jagged line: the radius wanders by a sixth on a scale of cm.
                    const double edge = 1.0 + 0.17 * fractalNoise(x, y, 12.0, 2, seed_ + 900);
                    if (p.distance2(x, c) < edge * edge) return 1.0;
                }
                return 0.0;
            }
            case IceKind::Ridges: {
                // In mm already, as the bead's: a ridge's width and height scale with the size.
                double thickness = 0.0;
                for (const Ridge& r : ridges_) {
                    const double along = smoothstep(r.spanFrom, r.spanFrom + 0.05, spanPos) *
                                         (1.0 - smoothstep(r.spanTo - 0.05, r.spanTo, spanPos));
                    const double centreMm = r.chord * chordMm + 0.03 * chordMm * std::sin(x / 25.0 + r.wavePhase);
                    const double t = (c * chordMm - centreMm) / (r.halfWidth * sizeMm_);
                    thickness = std::max(thickness, r.height * sizeMm_ * along * beadProfile(std::abs(t)));
                }
                return thickness;
            }
            case IceKind::Icicles:
                // The runback band the icicles grew from, in mm as theirs: over the chord's last
                // sixth, thickest on the edge, where the icicles' roots stand on it.
                return 0.3 * sizeMm_ * smoothstep(0.83, 0.97, c) * icicleSpan(icicles_, spanPos);
        }
        return 0.0;
    }

    const Bead& bead() const { return bead_; }

private:
    IceKind kind_;
    std::uint32_t seed_;
    double sizeMm_;
    Bead bead_;
    std::vector<Patch> patches_;
    std::vector<Ridge> ridges_;
    std::vector<Icicle> icicles_;
};

double chordAt(double spanPos) { return kRootChordMm + (kTipChordMm - kRootChordMm) * spanPos; }

}  // namespace

GridSurface bladeSurface(IceKind ice, std::uint32_t seed, double beadOverMm) {
    const IceShape iceShape(ice, seed, beadOverMm);
    GridSurface s;
    s.nu = 410;
    // A ridge a few mm across, or a sheet's broken edge, needs stations closer than 2 mm.
    s.nv = ice == IceKind::Ridges || ice == IceKind::Shed ? 288 : 96;
    s.local.resize(static_cast<std::size_t>(s.nu + 1) * (s.nv + 1));
    s.ice.resize(s.local.size());
    for (int j = 0; j <= s.nv; ++j) {
        const double c = 0.5 * (1.0 - std::cos(kPi * j / s.nv));  // dense at both edges
        for (int i = 0; i <= s.nu; ++i) {
            const double spanPos = static_cast<double>(i) / s.nu;
            const double x = (spanPos - 0.5) * kBladeLengthMm;
            const double chord = chordAt(spanPos);
            const double y = (c - kPitchAxisChord) * chord;
            const double h = 5.0 * kAirfoilThickness * chord *
                             (0.2969 * std::sqrt(c) - 0.1260 * c - 0.3516 * c * c + 0.2843 * c * c * c -
                              0.1036 * c * c * c * c);
            s.local[s.index(i, j)] = {x, y, std::max(0.0, h)};
            s.ice[s.index(i, j)] = static_cast<float>(iceShape(spanPos, c, chord, x, y));
        }
    }
    return s;
}

GridSurface beadFront(IceKind ice, std::uint32_t seed, double beadOverMm) {
    GridSurface s;
    if (ice != IceKind::Bead && ice != IceKind::BeadGlaze) return s;
    const Bead bead = drawBead(seed, beadOverMm);
    s.nu = 410;  // the blade's span stations, so that the front meets the blade along its edge
    s.nv = 16;
    s.local.resize(static_cast<std::size_t>(s.nu + 1) * (s.nv + 1));
    s.ice.resize(s.local.size());
    for (int j = 0; j <= s.nv; ++j) {
        const double t = static_cast<double>(j) / s.nv;  // 0 on the leading edge .. 1 at the bead's front
        for (int i = 0; i <= s.nu; ++i) {
            const double spanPos = static_cast<double>(i) / s.nu;
            const double x = (spanPos - 0.5) * kBladeLengthMm;
            const double leadingEdgeY = -kPitchAxisChord * chordAt(spanPos);
            // On the chord plane, where the leading edge is: the bead's footing in front of it.
            s.local[s.index(i, j)] = {x, leadingEdgeY - t * bead.frontMm, 0.0};
            s.ice[s.index(i, j)] =
                static_cast<float>(bead.heightMm * beadAlongSpan(spanPos, x, leadingEdgeY, seed) * beadProfile(t));
        }
    }
    return s;
}

GridSurface icicleFront(std::uint32_t seed, double sizeMm, double lengthScale) {
    std::vector<Icicle> icicles = drawIcicles(seed);
    for (Icicle& i : icicles) i.length *= lengthScale;
    double longestMm = 0.0;
    for (const Icicle& i : icicles) longestMm = std::max(longestMm, i.length * sizeMm);
    GridSurface s;
    s.nu = 1640;  // half a millimetre along the span: an icicle's tip is narrow
    s.nv = 96;
    s.local.resize(static_cast<std::size_t>(s.nu + 1) * (s.nv + 1));
    s.ice.resize(s.local.size());
    for (int j = 0; j <= s.nv; ++j) {
        const double outMm = longestMm * j / s.nv;  // 0 on the trailing edge .. the longest icicle's tip
        for (int i = 0; i <= s.nu; ++i) {
            const double spanPos = static_cast<double>(i) / s.nu;
            const double x = (spanPos - 0.5) * kBladeLengthMm;
            s.local[s.index(i, j)] = {x, (1.0 - kPitchAxisChord) * chordAt(spanPos) + outMm, 0.0};
            double thickness = 0.0;
            for (const Icicle& icicle : icicles) {
                const double lengthMm = icicle.length * sizeMm;
                if (outMm >= lengthMm) continue;
                // A half-cone: its radius tapers from the root to the tip, its section a half-round.
                const double radiusMm = icicle.rootRadius * sizeMm * (1.0 - outMm / lengthMm);
                const double acrossMm = x - (icicle.spanPos - 0.5) * kBladeLengthMm;
                thickness = std::max(thickness, std::sqrt(std::max(0.0, radiusMm * radiusMm - acrossMm * acrossMm)));
            }
            s.ice[s.index(i, j)] = static_cast<float>(thickness);
        }
    }
    return s;
}

GridSurface glazeEdge(const GridSurface& blade, bool leading) {
    GridSurface s;
    s.nu = blade.nu;
    s.nv = 8;
    s.local.resize(static_cast<std::size_t>(s.nu + 1) * (s.nv + 1));
    s.ice.resize(s.local.size());
    const int edgeRow = leading ? 0 : blade.nv;
    const double outwards = leading ? -1.0 : 1.0;  // the leading edge at -y
    for (int j = 0; j <= s.nv; ++j) {
        const double t = static_cast<double>(j) / s.nv;  // 0 on the edge .. 1 as far out as the ice is thick
        for (int i = 0; i <= s.nu; ++i) {
            const cv::Vec3d& edge = blade.local[blade.index(i, edgeRow)];
            const double thicknessMm = blade.ice[blade.index(i, edgeRow)];
            s.local[s.index(i, j)] = {edge[0], edge[1] + outwards * t * thicknessMm, edge[2]};
            s.ice[s.index(i, j)] = static_cast<float>(thicknessMm * std::sqrt(std::max(0.0, 1.0 - t * t)));
        }
    }
    return s;
}

Mesh glazeEdgeMesh(const GridSurface& edge, const Pose& pose, const Look& look) {
    Mesh mesh = bladeMesh(edge, 1.0, pose, look, kMaterialGlazeEdge);
    // Lit as the plane it lies on: what shows through it is the table's light there, or the sky's.
    const float flat = lambert(look, pose.rotation * cv::Vec3d(0, 0, -1));
    for (VertexAttributes& a : mesh.attributes) a[kAttributeShade] = flat;
    return mesh;
}

Mesh bladeMesh(const GridSurface& s, double iceScale, const Pose& pose, const Look& look, int material,
               IceOptics optics) {
    Mesh mesh;
    mesh.material = material;
    mesh.vertices.resize(s.local.size());
    for (std::size_t k = 0; k < s.local.size(); ++k) {
        const cv::Vec3d& p = s.local[k];
        mesh.vertices[k] = pose.toCamera(p[0], p[1], p[2] + iceScale * s.ice[k]);
    }
    const auto normals = gridNormals(s, mesh.vertices);
    mesh.attributes.resize(s.local.size());
    for (std::size_t k = 0; k < s.local.size(); ++k) {
        const auto a = static_cast<float>(s.local[k][0]), b = static_cast<float>(s.local[k][1]);
        mesh.attributes[k] = {a, b, lambert(look, normals[k]), static_cast<float>(iceScale * s.ice[k]), a, b, 0.0f};
    }
    mesh.triangles = gridTriangles(s.nu, s.nv);
    mesh.normals = normals;
    mesh.towardsLight = look.towardsLight;
    if (optics == IceOptics::Refractive && iceScale > 0 && material == kMaterialBlade) {
        // The blade under its ice, for each eye to see through it (refraction.hpp). Its surface
        // coordinates are the object frame's x and y: (x, y) = Rᵀ·(p − t), the first two rows.
        ClearLayer layer;
        layer.under.resize(s.local.size());
        for (std::size_t k = 0; k < s.local.size(); ++k) {
            const cv::Vec3d& p = s.local[k];
            layer.under[k] = pose.toCamera(p[0], p[1], p[2]);
        }
        layer.underNormal = gridNormals(s, layer.under);
        layer.normal = normals;
        const cv::Matx33d toObject = pose.rotation.t();
        layer.textureAxes = cv::Matx23d(toObject(0, 0), toObject(0, 1), toObject(0, 2),
                                        toObject(1, 0), toObject(1, 1), toObject(1, 2));
        layer.textureOrigin = pose.translation;
        mesh.clearLayer = std::move(layer);
    }
    return mesh;
}

std::vector<cv::Vec3d> bladeOutline(const GridSurface& s, const Pose& pose, int stride) {
    std::vector<cv::Vec3d> outline;
    for (int i = 0; i <= s.nu; i += stride) {
        const cv::Vec3d& p = s.local[s.index(i, 0)];
        outline.push_back(pose.toCamera(p[0], p[1], 0));
    }
    for (int i = s.nu; i >= 0; i -= stride) {
        const cv::Vec3d& p = s.local[s.index(i, s.nv)];
        outline.push_back(pose.toCamera(p[0], p[1], 0));
    }
    return outline;
}

}  // namespace icewatch::synth
