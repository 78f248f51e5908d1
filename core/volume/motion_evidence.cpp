// The object's motion between the captures from the texture that did not change (motion_evidence.hpp).
#include "core/volume/motion_evidence.hpp"

#include <algorithm>
#include <cmath>

#include <opencv2/calib3d.hpp>
#include <sstream>

namespace icewatch::volume {

namespace {

struct Evidence {
    std::vector<PointPair> pairs;
    std::vector<std::size_t> track;  // index into the tracks for each pair
};

Evidence gather(const std::vector<TextureTrack>& tracks, bool onObject, const PlaneFrame& plane, double bandMm) {
    Evidence e;
    for (std::size_t i = 0; i < tracks.size(); ++i) {
        const TextureTrack& t = tracks[i];
        if (t.onObject != onObject || t.state != TextureTrack::State::Unchanged) continue;
        if (!onObject && std::abs(plane.toPlane(t.baselineMm).z) > bandMm) continue;
        e.pairs.push_back({t.currentMm, t.baselineMm, t.covarianceMm2});
        e.track.push_back(i);
    }
    return e;
}

// The fit's options as a fitted motion judges its pairs: with the covariance scale it found.
RigidMotionOptions judgedBy(const RigidMotionOptions& fit, const RigidMotion& motion) {
    RigidMotionOptions judged = fit;
    judged.covarianceScale = motion.covarianceScale;
    return judged;
}

int countAgreeing(const Evidence& e, const RigidMotion& motion, const RigidMotionOptions& fit) {
    const RigidMotionOptions o = judgedBy(fit, motion);
    int agreeing = 0;
    for (const PointPair& p : e.pairs) agreeing += pairAgrees(p, motion.transform, o) ? 1 : 0;
    return agreeing;
}

double shareAgreeing(const Evidence& e, const RigidMotion& motion, const RigidMotionOptions& fit) {
    if (e.pairs.empty()) return 0.0;
    return static_cast<double>(countAgreeing(e, motion, fit)) / static_cast<double>(e.pairs.size());
}

// Share of the pairs that, moved by `motion`, stayed or rose along the plane's normal: not sunk
// (the rise above -3 σ) and moved within the plane by less than 3 σ or than they rose, whichever
// is more. Ice that kept the texture raises the texture seen through it along the normal where it
// is thick enough to tell, and not at all where it is thinner than the noise; a wet glaze's
// highlights and its refraction also move where each patch is found a little aside, by a
// fraction of the rise (rendered: a glaze with gloss 0.5 on a table, unmoved, rose 2.4 mm at the
// median and moved aside by 0.1 mm, over 3 σ for 29 % of its samples, so that asking for 3 σ
// aside took the glaze's surface for the object's motion and read -92 % as ok). An object pushed
// along its table or its rig moves within the plane, not only towards the camera.
double shareStillOrRisen(const Evidence& e, const RigidMotion& motion, const PlaneFrame& plane,
                         const RigidMotionOptions& fit) {
    if (e.pairs.empty()) return 0.0;
    const RigidMotionOptions o = judgedBy(fit, motion);
    int still = 0;
    for (const PointPair& p : e.pairs) {
        const cv::Vec3d r = motion.transform.apply(p.current) - p.baseline;
        const cv::Matx33d c = pairCovariance(p, o);
        auto sigmaAlong = [&c](const cv::Vec3d& axis) { return std::sqrt((axis.t() * c * axis)(0)); };
        const double rise = r.dot(plane.normal);
        const bool inPlane = std::abs(r.dot(plane.axisU)) < std::max(3 * sigmaAlong(plane.axisU), rise) &&
                             std::abs(r.dot(plane.axisV)) < std::max(3 * sigmaAlong(plane.axisV), rise);
        still += inPlane && rise > -3 * sigmaAlong(plane.normal) ? 1 : 0;
    }
    return static_cast<double>(still) / static_cast<double>(e.pairs.size());
}

Evidence join(const Evidence& a, const Evidence& b) {
    Evidence j = a;
    j.pairs.insert(j.pairs.end(), b.pairs.begin(), b.pairs.end());
    j.track.insert(j.track.end(), b.track.begin(), b.track.end());
    return j;
}

// The share of the object's extent that the unchanged samples agreeing with `motion` span.
double objectSpan(const std::vector<TextureTrack>& tracks, const std::vector<std::uint8_t>& clean,
                  const PlaneFrame& plane) {
    std::vector<cv::Vec3d> samples;
    std::vector<std::uint8_t> support;
    for (std::size_t i = 0; i < tracks.size(); ++i) {
        if (!tracks[i].onObject || !(tracks[i].baselineMm[2] > 0)) continue;
        samples.push_back(tracks[i].baselineMm);
        support.push_back(clean[i]);
    }
    return supportSpanPercent(samples, support, RigidTransform{}, plane);
}

// `of` as a left perturbation of `base`: of = exp(ω)·base + δt.
cv::Vec6d perturbation(const RigidTransform& base, const RigidTransform& of) {
    const cv::Matx33d dr = of.rotation * base.rotation.t();
    cv::Vec3d omega;
    cv::Rodrigues(cv::Mat(dr), omega);
    const cv::Vec3d dt = of.translation - dr * base.translation;
    return {omega[0], omega[1], omega[2], dt[0], dt[1], dt[2]};
}

// Leave-one-band-out refits of the evidence, bands of equal count along the plane's u axis.
std::vector<cv::Vec6d> jackknife(const Evidence& used, const RigidTransform& fitted, const PlaneFrame& plane,
                                 const RigidMotionOptions& fit, int groups, int minPairs) {
    std::vector<cv::Vec6d> deltas;
    const std::size_t n = used.pairs.size();
    if (groups < 2 || n < static_cast<std::size_t>(groups * 3)) return deltas;
    std::vector<std::size_t> order(n);
    for (std::size_t i = 0; i < n; ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        return plane.toPlane(used.pairs[a].baseline).x < plane.toPlane(used.pairs[b].baseline).x;
    });
    // The refits are independent, each with its own draws: side by side, in order afterwards.
    std::vector<RigidMotion> refits(static_cast<std::size_t>(groups));
    cv::parallel_for_(cv::Range(0, groups), [&](const cv::Range& range) {
        for (int g = range.start; g < range.end; ++g) {
            const std::size_t lo = n * static_cast<std::size_t>(g) / static_cast<std::size_t>(groups);
            const std::size_t hi = n * static_cast<std::size_t>(g + 1) / static_cast<std::size_t>(groups);
            std::vector<PointPair> kept;
            for (std::size_t k = 0; k < n; ++k)
                if (k < lo || k >= hi) kept.push_back(used.pairs[order[k]]);
            refits[static_cast<std::size_t>(g)] = fitRigidMotion(kept, fit, minPairs);
        }
    });
    for (const RigidMotion& m : refits)
        if (m.ok) deltas.push_back(perturbation(fitted, m.transform));
    return deltas;
}

// How the brightness of the evidence's samples changed: how far their median ratio departs from
// the light's (0 when the light is not known), and how widely the middle half of them spread about
// it (their interquartile range over the median; 0 without evidence).
struct EvidenceLight {
    double shift = 0;
    double spread = 0;
};
EvidenceLight evidenceLight(const Evidence& e, const std::vector<TextureTrack>& tracks,
                            std::optional<double> lightRatio) {
    EvidenceLight light;
    if (e.track.empty()) return light;
    std::vector<double> ratios;
    ratios.reserve(e.track.size());
    for (std::size_t i : e.track) ratios.push_back(tracks[i].brightnessRatio);
    std::sort(ratios.begin(), ratios.end());
    const double median = ratios[ratios.size() / 2];
    if (!(median > 0)) return light;
    if (lightRatio && *lightRatio > 0) light.shift = median / *lightRatio - 1.0;
    light.spread = (ratios[3 * ratios.size() / 4] - ratios[ratios.size() / 4]) / median;
    return light;
}

}  // namespace

MotionEstimate estimateMotion(const std::vector<TextureTrack>& tracks, const PlaneFrame& plane,
                              const MotionEvidenceOptions& o) {
    MotionEstimate out;
    out.clean.assign(tracks.size(), 0);
    const Evidence object = gather(tracks, true, plane, 0.0);
    const Evidence background = gather(tracks, false, plane, o.backgroundBandMm);
    // On the object, a rise towards the camera is ice, not motion; the background carries none.
    RigidMotionOptions fit = o.fit;
    fit.riseAxis = plane.normal;
    const RigidMotion onObject = fitRigidMotion(object.pairs, fit, o.minPairs);
    const RigidMotion onBackground = fitRigidMotion(background.pairs, o.fit, o.minPairs);

    auto cleanUnder = [&](const RigidMotion& motion) {
        const RigidMotionOptions judged = judgedBy(fit, motion);
        std::vector<std::uint8_t> clean(tracks.size(), 0);
        for (std::size_t k = 0; k < object.pairs.size(); ++k) {
            clean[object.track[k]] = pairAgrees(object.pairs[k], motion.transform, judged) ? 1 : 0;
        }
        return clean;
    };
    const double objectSpanPercent = onObject.ok ? objectSpan(tracks, cleanUnder(onObject), plane) : 0.0;
    const EvidenceLight objectLight = evidenceLight(object, tracks, o.lightRatio);
    const bool objectKeptItsLight = std::abs(objectLight.shift) <= o.maxEvidenceLightShift &&
                                    objectLight.spread <= o.maxEvidenceLightSpread;
    const bool objectAloneKeptItsLight = objectKeptItsLight && objectLight.spread <= o.maxObjectAloneLightSpread;
    const bool objectSuffices = onObject.ok && objectSpanPercent >= o.minSupportSpanPercent && objectAloneKeptItsLight;
    // Why the object's own texture does not fix its motion when it changed against the light.
    auto lightReason = [&] {
        std::ostringstream reason;
        reason.precision(3);
        reason << "the object's unchanged texture (" << object.pairs.size() << " samples) ";
        if (std::abs(objectLight.shift) > o.maxEvidenceLightShift) {
            reason << (objectLight.shift > 0 ? "brightened" : "darkened") << " by " << 100.0 * std::abs(objectLight.shift)
                   << " % against the light on its background (at most " << 100.0 * o.maxEvidenceLightShift << " %)";
        } else {
            // Beyond the bound every use of the texture has, or only beyond the tighter one for
            // texture that alone fixes the motion.
            const bool beyondShared = objectLight.spread > o.maxEvidenceLightSpread;
            reason << "changed its brightness unevenly (the middle half of it over " << 100.0 * objectLight.spread
                   << " %, at most " << 100.0 * (beyondShared ? o.maxEvidenceLightSpread : o.maxObjectAloneLightSpread)
                   << (beyondShared ? " %)" : " % where the object alone fixes its motion)");
        }
        // What tells the two apart is a capture under the baseline's light: a layer still changes
        // the texture's brightness then, light no longer does. Said, so that whoever reads the
        // refusal on a sunny day knows what to do rather than only what went wrong.
        reason << ": it may lie under a thin layer over all of the object, or the light changed on the object "
                  "alone, and does not fix the object's motion (a capture under the baseline's light, overcast "
                  "or at the baseline's time of day, tells the two apart)";
        return reason.str();
    };
    out.objectLightShift = objectLight.shift;
    out.objectLightSpread = objectLight.spread;
    out.objectLightShifted = !objectKeptItsLight;

    RigidMotion chosen;
    Evidence used;
    RigidMotionOptions usedFit = fit;
    if (onBackground.ok) {
        const bool littleOnObject = static_cast<int>(object.pairs.size()) < o.minPairs;
        if (littleOnObject) {
            chosen = onBackground;
            used = background;
            usedFit = o.fit;
            out.source = "background";
        } else if (shareAgreeing(object, onBackground, fit) >= o.agreeShare) {
            used = join(object, background);
            chosen = fitRigidMotion(used.pairs, fit, o.minPairs);
            out.source = "object+background";
        } else if (shareStillOrRisen(object, onBackground, plane, o.fit) >= o.agreeShare) {
            chosen = onBackground;
            used = background;
            usedFit = o.fit;
            out.source = "background";
        } else if (objectSuffices) {
            chosen = onObject;
            used = object;
            out.source = "object";
        } else {
            out.reason = !objectAloneKeptItsLight ? lightReason() + ", and it moved otherwise than its background"
                                         : "the object's unchanged texture moved otherwise than its background and "
                                           "spans too little of the object to fix its motion alone";
            return out;
        }
    } else if (objectSuffices) {
        chosen = onObject;
        used = object;
        out.source = "object";
    } else if (!objectAloneKeptItsLight) {
        out.reason = "the motion between the captures is not observable: " + lightReason() +
                     "; no background it rests on was found";
        return out;
    } else {
        std::ostringstream reason;
        reason.precision(3);
        reason << "the motion between the captures is not observable: unchanged texture ("
               << object.pairs.size() << " samples) spans " << objectSpanPercent << " % of the object (min "
               << o.minSupportSpanPercent << " %) and no background it rests on was found";
        out.reason = reason.str();
        return out;
    }
    if (!chosen.ok) {
        out.reason = "the unchanged texture does not agree on one rigid motion";
        return out;
    }
    out.ok = true;
    out.transform = chosen.transform;
    out.covariance = chosen.covariance;
    out.chi2PerDof = chosen.chi2PerDof;
    out.clean = cleanUnder(chosen);
    for (std::uint8_t c : out.clean) out.objectEvidence += c;
    if (out.source != "object") out.backgroundEvidence = countAgreeing(background, chosen, fit);
    out.supportSpanPercent = objectSpan(tracks, out.clean, plane);
    out.jackknife = jackknife(used, chosen.transform, plane, usedFit, o.jackknifeGroups, o.minPairs);
    return out;
}

}  // namespace icewatch::volume
