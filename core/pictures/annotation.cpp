// What is drawn over a picture for a person: the region's outline and a line of text (a refusal's
// reason), both sized for the picture so they are legible at 1280x720 and on small test images.
#include "core/pictures/annotation.hpp"

#include <algorithm>
#include <sstream>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "core/common/error.hpp"

namespace icewatch::pictures {

namespace {

constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
// Magenta: in no colour map and not a grey, so it stands out on both kinds of picture.
const cv::Scalar kOutline(255, 0, 255);

// Words laid into lines no wider than `width` pixels; a word longer than a line gets its own.
std::vector<std::string> wrap(const std::string& text, int width, double font, int thickness) {
    std::vector<std::string> lines;
    std::istringstream words(text);
    std::string word, line;
    int baseline = 0;
    while (words >> word) {
        const std::string candidate = line.empty() ? word : line + " " + word;
        if (!line.empty() && cv::getTextSize(candidate, kFont, font, thickness, &baseline).width > width) {
            lines.push_back(line);
            line = word;
        } else {
            line = candidate;
        }
    }
    if (!line.empty()) lines.push_back(line);
    return lines;
}

}  // namespace

double fontScaleFor(int imageRows) { return std::clamp(imageRows / 800.0, 0.35, 1.2); }

void drawOutline(cv::Mat& picture, const cv::Mat& region) {
    if (region.empty()) return;
    if (region.size() != picture.size() || region.type() != CV_8U) {
        throw InvalidInput("outline: the region must be an 8-bit mask of the picture's size");
    }
    std::vector<std::vector<cv::Point>> contours;
    cv::findContours(region.clone(), contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_SIMPLE);
    cv::drawContours(picture, contours, -1, kOutline, std::max(1, picture.rows / 400), cv::LINE_8);
}

cv::Rect writeBanner(cv::Mat& picture, const std::string& text) {
    if (picture.type() != CV_8UC3) throw InvalidInput("banner: the picture must be 8-bit BGR");
    const double font = fontScaleFor(picture.rows);
    const int thickness = font >= 0.9 ? 2 : 1;
    int baseline = 0;
    const int lineHeight = cv::getTextSize("Ag", kFont, font, thickness, &baseline).height * 2;
    const int margin = lineHeight / 3;
    const std::vector<std::string> lines = wrap(text, picture.cols - 2 * margin, font, thickness);
    const int height = std::min(picture.rows, static_cast<int>(lines.size()) * lineHeight + 2 * margin);
    const cv::Rect band(0, 0, picture.cols, height);
    cv::Mat area = picture(band);
    area.setTo(cv::Scalar(30, 30, 30));
    for (std::size_t i = 0; i < lines.size(); ++i) {
        const int y = margin + static_cast<int>(i + 1) * lineHeight - lineHeight / 4;
        cv::putText(picture, lines[i], {margin, y}, kFont, font, cv::Scalar(255, 255, 255), thickness, cv::LINE_AA);
    }
    return band;
}

}  // namespace icewatch::pictures
