// A capture as the float average of the frames that showed the same still scene (capture_average.hpp).
//
// Streaming rather than choosing a reference after the burst: holding every frame of a 16-frame
// burst at 3840x1080 took about 200 MB in BGR alone; a two-pass over re-decoded frames would work
// for recordings but not for the daemon, whose camera hands each frame over once.
#include "core/volume/capture_average.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include <opencv2/imgproc.hpp>

#include "core/common/error.hpp"
#include "core/health/image_health.hpp"
#include "core/volume/robust_statistics.hpp"

namespace icewatch::volume {

namespace {

// Why the frames were dropped, for a refusal: the first frame of each cause in full, the others
// counted. A burst under the same fault drops every frame alike, and a reason naming all sixteen
// would bury the cause on the operator's screen and in the JSON that SCADA reads.
std::string droppedSummary(const std::vector<DroppedFrame>& dropped) {
    std::vector<std::pair<const DroppedFrame*, int>> causes;  // the first of each flag, and how many
    for (const DroppedFrame& d : dropped) {
        const auto same = std::find_if(causes.begin(), causes.end(),
                                       [&d](const auto& c) { return c.first->flag == d.flag; });
        if (same == causes.end()) causes.emplace_back(&d, 1);
        else ++same->second;
    }
    std::string summary;
    for (const auto& [first, count] : causes) {
        summary += "; " + first->reason;
        if (count > 1) summary += " (and " + std::to_string(count - 1) + " more frames: " + first->flag + ")";
    }
    return summary;
}

cv::Mat greyOf(const cv::Mat& frame) {
    if (frame.channels() == 1) return frame;
    cv::Mat grey;
    cv::cvtColor(frame, grey, cv::COLOR_BGR2GRAY);
    return grey;
}

// Half-size float copy, lightly smoothed: enough to see a shift or a bird, four times cheaper to
// compare, and smooth enough for a gradient step.
cv::Mat small(const cv::Mat& grey) {
    cv::Mat f, out;
    grey.convertTo(f, CV_32F);
    cv::resize(f, out, {}, 0.5, 0.5, cv::INTER_AREA);
    cv::GaussianBlur(out, out, {0, 0}, 1.0);
    return out;
}

// The global shift of `b` against `a` (full-size pixels), by one least-squares gradient step over
// the whole image: exact enough for the fractions of a pixel that matter here, and a frame that
// moved by more reads more than the limit all the same.
cv::Point2d globalShift(const cv::Mat& a, const cv::Mat& b) {
    cv::Mat gx, gy;
    cv::Sobel(a, gx, CV_32F, 1, 0, 3, 1.0 / 8.0);
    cv::Sobel(a, gy, CV_32F, 0, 1, 3, 1.0 / 8.0);
    const cv::Mat diff = b - a;
    const double xx = gx.dot(gx), xy = gx.dot(gy), yy = gy.dot(gy);
    const double bx = -gx.dot(diff), by = -gy.dot(diff);
    const double det = xx * yy - xy * xy;
    if (det <= 1e-12) return {0, 0};
    return cv::Point2d((yy * bx - xy * by) / det, (xx * by - xy * bx) / det) * 2.0;
}

// Share of pixels (percent) whose difference stands out of the difference's own noise. The
// median and its spread are read on every 4th pixel of every 4th row (some 65 000 at 3840x1080,
// plenty for two order statistics, and a sixteenth of the selection work a frame during a burst);
// every pixel is then counted against them.
double changedPercent(const cv::Mat& a, const cv::Mat& b) {
    cv::Mat diff = a - b;
    constexpr int kStride = 4;
    std::vector<float> values;
    values.reserve(static_cast<std::size_t>((diff.rows / kStride + 1) * (diff.cols / kStride + 1)));
    for (int y = 0; y < diff.rows; y += kStride) {
        const float* row = diff.ptr<float>(y);
        for (int x = 0; x < diff.cols; x += kStride) values.push_back(row[x]);
    }
    const float centre = median(values);
    const double sigma = std::max(0.5, spreadAbout(std::move(values), centre));
    const double cut = 6.0 * sigma;
    std::size_t count = 0;
    for (int y = 0; y < diff.rows; ++y) {
        const float* row = diff.ptr<float>(y);
        for (int x = 0; x < diff.cols; ++x) count += std::abs(row[x] - centre) > cut ? 1 : 0;
    }
    return 100.0 * static_cast<double>(count) / static_cast<double>(diff.total());
}


// How a frame compares with a group's reference: an empty flag when it shows the same still scene.
struct Verdict {
    std::string flag;  // "", "moved" or "disturbed"
    std::string why;
};

Verdict compare(const cv::Mat& reference, const cv::Mat& frame, const CaptureAverageOptions& o) {
    const cv::Point2d shift = globalShift(reference, frame);
    if (std::hypot(shift.x, shift.y) > o.maxFrameShiftPx) {
        std::ostringstream why;
        why.precision(2);
        why << "moved " << std::hypot(shift.x, shift.y) << " px against the others (max " << o.maxFrameShiftPx << ")";
        return {"moved", why.str()};
    }
    const double changed = changedPercent(reference, frame);
    if (changed > o.maxChangedPercent) {
        std::ostringstream why;
        why.precision(2);
        why << changed << " % of the image changed against the others (something passed)";
        return {"disturbed", why.str()};
    }
    return {};
}

// Frames that showed one scene: the first one's half-size image, the full-size sum, and the sum
// with every other frame taken away instead of added, where the scene cancels and the noise stays.
struct Group {
    cv::Mat reference;
    cv::Mat sum;          // CV_32F: a sum of up to 65 793 8-bit frames is exact
    cv::Mat alternating;  // CV_32F: + the 1st, 3rd, ... frame, - the 2nd, 4th, ...
    int count = 0;
};

// One draw of the average's own noise: the frames combined with weights that sum to zero, so the
// still scene cancels, and whose squares sum to 1/n, so the noise has the average's variance and
// spectrum (each frame's JPEG encoding and all). Even n: the alternating sum over n. Odd n: it
// keeps one frame's scene, which the average takes off; the weights ±1 - 1/n then square to
// n - 1/n, and 1/sqrt(n² - 1) rescales them to 1/n.
cv::Mat averageNoise(const Group& g) {
    const double n = g.count;
    if (g.count < 2) return {};
    if (g.count % 2 == 0) return g.alternating / n;
    cv::Mat noise = g.alternating - g.sum / n;
    return noise * (1.0 / std::sqrt(n * n - 1.0));
}

struct FrameRecord {
    std::string name;
    int group = -1;       // -1: in neither
    Verdict versus[2];    // against each group's reference, where it was compared
    bool compared[2] = {false, false};
};

}  // namespace

struct CaptureAccumulator::Impl {
    CaptureAverageOptions options;
    cv::Size size;
    std::vector<FrameRecord> healthy;
    std::vector<DroppedFrame> unhealthy;
    int framesAdded = 0;
    std::vector<Group> groups;  // at most two
    Verdict secondOpened;       // why the second group's first frame disagreed with the first's

    void join(std::size_t group, const cv::Mat& grey) {
        Group& g = groups[group];
        cv::accumulate(grey, g.sum);
        if (g.count % 2 == 0) cv::accumulate(grey, g.alternating);
        else cv::subtract(g.alternating, grey, g.alternating, cv::noArray(), CV_32F);
        ++g.count;
        healthy.back().group = static_cast<int>(group);
    }
    void open(const cv::Mat& small, const cv::Mat& grey) {
        groups.push_back({small, cv::Mat::zeros(grey.size(), CV_32F), cv::Mat::zeros(grey.size(), CV_32F), 0});
        join(groups.size() - 1, grey);
    }
};

CaptureAccumulator::CaptureAccumulator(const CaptureAverageOptions& options) : impl_(std::make_unique<Impl>()) {
    impl_->options = options;
}
CaptureAccumulator::~CaptureAccumulator() = default;
CaptureAccumulator::CaptureAccumulator(CaptureAccumulator&&) noexcept = default;
CaptureAccumulator& CaptureAccumulator::operator=(CaptureAccumulator&&) noexcept = default;

int CaptureAccumulator::framesAdded() const { return impl_->framesAdded; }

void CaptureAccumulator::add(const cv::Mat& frame, const std::string& givenName) {
    Impl& a = *impl_;
    const std::string name = givenName.empty() ? "frame " + std::to_string(a.framesAdded + 1) : givenName;
    if (frame.empty() || frame.depth() != CV_8U || (a.framesAdded > 0 && frame.size() != a.size)) {
        throw InvalidInput(name + ": not an 8-bit frame of the capture's size");
    }
    if (a.framesAdded++ == 0) a.size = frame.size();
    const cv::Mat grey = greyOf(frame);
    const int half = grey.cols / 2;
    for (const auto& [eye, which] : {std::pair{cv::Rect(0, 0, half, grey.rows), "left eye"},
                                     std::pair{cv::Rect(half, 0, half, grey.rows), "right eye"}}) {
        const health::ImageHealth h = health::checkImageHealth(grey(eye), a.options.health);
        if (!h.ok()) {
            a.unhealthy.push_back({h.problems.front().flag, name + ": " + which + ": " + h.problems.front().reason});
            return;
        }
    }
    a.healthy.push_back({name, -1, {}, {}});
    const cv::Mat reduced = small(grey);
    if (a.groups.empty()) {
        a.open(reduced, grey);
        return;
    }
    FrameRecord& record = a.healthy.back();
    for (std::size_t g = 0; g < a.groups.size(); ++g) {
        record.versus[g] = compare(a.groups[g].reference, reduced, a.options);
        record.compared[g] = true;
        if (record.versus[g].flag.empty()) {
            a.join(g, grey);
            return;
        }
    }
    if (a.groups.size() == 1) {
        a.secondOpened = record.versus[0];
        a.open(reduced, grey);
    }
}

AveragedCapture CaptureAccumulator::finish() {
    Impl a = std::move(*impl_);
    impl_ = std::make_unique<Impl>();
    impl_->options = a.options;
    AveragedCapture out;
    out.dropped = a.unhealthy;
    out.framesHealthy = static_cast<int>(a.healthy.size());
    const int winner = a.groups.size() == 2 && a.groups[1].count > a.groups[0].count ? 1 : 0;
    for (const FrameRecord& f : a.healthy) {
        if (f.group == winner) continue;
        // A frame of the losing first group was never compared with the second group's reference;
        // it disagrees with it as that reference disagreed with the first group's.
        const Verdict& v = f.compared[winner] ? f.versus[winner] : a.secondOpened;
        out.dropped.push_back({v.flag, f.name + ": " + v.why});
    }
    const int used = a.groups.empty() ? 0 : a.groups[static_cast<std::size_t>(winner)].count;
    const int needed = std::max(1, a.options.minFrames);
    if (used < needed) {
        out.reason = std::to_string(used) + " usable frames of " + std::to_string(a.framesAdded) + " (" +
                     std::to_string(needed) + " needed)";
        out.reason += droppedSummary(out.dropped);
        return out;
    }
    Group& group = a.groups[static_cast<std::size_t>(winner)];
    out.frame = group.sum / static_cast<double>(group.count);
    out.noise = averageNoise(group);
    out.framesUsed = group.count;
    return out;
}

AveragedCapture averageCapture(const std::vector<cv::Mat>& frames, const std::vector<std::string>& names,
                               const CaptureAverageOptions& o) {
    if (frames.empty()) throw InvalidInput("capture: no frames");
    CaptureAccumulator accumulator(o);
    for (std::size_t i = 0; i < frames.size(); ++i) accumulator.add(frames[i], i < names.size() ? names[i] : "");
    return accumulator.finish();
}

}  // namespace icewatch::volume
