// False colour on a fixed scale, and the colour bar that says what the colours mean. One colour
// map for the whole project (disparity pictures of `icewatch match`, the volume chain's pictures,
// the PLY cloud), so that a colour reads the same everywhere.
//
// Turbo rather than Jet: its lightness rises and falls smoothly, so a person sees no bands that
// are not in the data, and its ends (dark blue, dark red) stay apart from the black of "no value".
#include "core/pictures/colour_scale.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#include <opencv2/imgproc.hpp>

#include "core/common/error.hpp"
#include "core/pictures/annotation.hpp"

namespace icewatch::pictures {

namespace {

const cv::Vec3b kBackground(40, 40, 40);
const cv::Scalar kText(255, 255, 255);
constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;

const std::array<cv::Vec3b, 256>& turbo() {
    static const std::array<cv::Vec3b, 256> table = [] {
        cv::Mat ramp(1, 256, CV_8U);
        for (int i = 0; i < 256; ++i) ramp.at<std::uint8_t>(0, i) = static_cast<std::uint8_t>(i);
        cv::Mat colours;
        cv::applyColorMap(ramp, colours, cv::COLORMAP_TURBO);
        std::array<cv::Vec3b, 256> out{};
        for (int i = 0; i < 256; ++i) out[static_cast<std::size_t>(i)] = colours.at<cv::Vec3b>(0, i);
        return out;
    }();
    return table;
}

int levelOf(double value, const ColourScale& scale) {
    const double t = (value - scale.lo) / (scale.hi - scale.lo);
    return static_cast<int>(std::lround(255.0 * std::clamp(t, 0.0, 1.0)));
}

std::string valueText(double value) {
    std::ostringstream text;
    text.precision(3);
    text << value;
    return text.str();
}

struct BarLayout {
    double font = 0.5;
    int thickness = 1;
    int margin = 0, lineHeight = 0, stripWidth = 0, rows = 0;
    cv::Rect bar;  // relative to the strip
};

// Sized from the picture's height alone, so the bar of every picture of one size sits in the same place.
BarLayout layoutFor(int imageRows) {
    BarLayout l;
    l.font = fontScaleFor(imageRows);
    l.thickness = l.font >= 0.9 ? 2 : 1;
    int baseline = 0;
    const cv::Size digit = cv::getTextSize("0", kFont, l.font, l.thickness, &baseline);
    const cv::Size word = cv::getTextSize("thickness", kFont, l.font, l.thickness, &baseline);
    const cv::Size number = cv::getTextSize("-0.000", kFont, l.font, l.thickness, &baseline);
    l.margin = std::max(4, digit.height);
    l.lineHeight = digit.height * 2;
    const int barWidth = std::max(12, imageRows / 30);
    l.stripWidth = std::max(word.width, barWidth + l.margin + number.width) + 2 * l.margin;
    const int top = l.margin + 2 * l.lineHeight;
    const int minBar = 6 * digit.height;
    l.rows = std::max(imageRows, top + minBar + l.margin + digit.height);
    l.bar = cv::Rect(l.margin, top, barWidth, l.rows - top - l.margin - digit.height);
    return l;
}

void putLine(cv::Mat& strip, const std::string& text, cv::Point origin, const BarLayout& l) {
    cv::putText(strip, text, origin, kFont, l.font, kText, l.thickness, cv::LINE_AA);
}

}  // namespace

cv::Vec3b colourOf(double value, const ColourScale& scale) {
    return turbo()[static_cast<std::size_t>(levelOf(value, scale))];
}

cv::Mat falseColour(const cv::Mat& values, const ColourScale& scale) {
    if (values.channels() != 1 || (values.depth() != CV_32F && values.depth() != CV_64F)) {
        throw InvalidInput("false colour: the map must be one channel of 32- or 64-bit float");
    }
    if (!(scale.hi > scale.lo)) throw InvalidInput("false colour: the scale's top must lie above its bottom");
    cv::Mat asDouble;
    values.convertTo(asDouble, CV_64F);
    cv::Mat colour(values.size(), CV_8UC3, cv::Scalar::all(0));
    for (int y = 0; y < values.rows; ++y) {
        const auto* v = asDouble.ptr<double>(y);
        auto* out = colour.ptr<cv::Vec3b>(y);
        for (int x = 0; x < values.cols; ++x) {
            if (std::isfinite(v[x])) out[x] = colourOf(v[x], scale);
        }
    }
    return colour;
}

cv::Rect colourBarRect(cv::Size imageSize) {
    const BarLayout l = layoutFor(imageSize.height);
    return l.bar + cv::Point(imageSize.width, 0);
}

cv::Mat withColourBar(const cv::Mat& picture, const ColourScale& scale) {
    if (picture.type() != CV_8UC3) throw InvalidInput("colour bar: the picture must be 8-bit BGR");
    const BarLayout l = layoutFor(picture.rows);
    cv::Mat out(l.rows, picture.cols + l.stripWidth, CV_8UC3, cv::Scalar(kBackground));
    picture.copyTo(out(cv::Rect(0, 0, picture.cols, picture.rows)));
    cv::Mat strip = out(cv::Rect(picture.cols, 0, l.stripWidth, l.rows));
    putLine(strip, scale.title, {l.margin, l.margin + l.lineHeight / 2}, l);
    putLine(strip, scale.unit, {l.margin, l.margin + l.lineHeight + l.lineHeight / 2}, l);
    const int last = std::max(1, l.bar.height - 1);
    for (int r = 0; r < l.bar.height; ++r) {
        const double value = scale.hi - (scale.hi - scale.lo) * r / last;
        strip(cv::Rect(l.bar.x, l.bar.y + r, l.bar.width, 1)).setTo(cv::Scalar(colourOf(value, scale)));
    }
    const int labelX = l.bar.x + l.bar.width + l.margin / 2;
    const int half = l.lineHeight / 4;
    putLine(strip, valueText(scale.hi), {labelX, l.bar.y + half * 2}, l);
    putLine(strip, valueText((scale.lo + scale.hi) / 2), {labelX, l.bar.y + l.bar.height / 2 + half}, l);
    putLine(strip, valueText(scale.lo), {labelX, l.bar.y + l.bar.height}, l);
    return out;
}

}  // namespace icewatch::pictures
