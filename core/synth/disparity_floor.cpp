// The noise floor of disparity for a rendered pair whose true disparity is known (see the header).
// Used to tell what a volume target asks of the images from what it asks of the matcher.
#include "core/synth/disparity_floor.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "core/common/error.hpp"

namespace icewatch::synth {

double DisparityFloor::meanSigmaPx(int pixels) const {
    if (pixels <= 0 || boxPx <= 0) return 0;
    return boxSigmaPx / std::sqrt(static_cast<double>(pixels) / (boxPx * boxPx));
}

DisparityFloor measureDisparityFloor(const cv::Mat& greyLeft, const cv::Mat& greyRight, const cv::Mat& trueDisparity,
                                     int boxPx) {
    if (greyLeft.empty() || greyLeft.channels() != 1 || greyRight.channels() != 1 ||
        greyLeft.size() != greyRight.size() || trueDisparity.type() != CV_32F || trueDisparity.size() != greyLeft.size()) {
        throw InvalidInput("disparity floor: two grey eyes and a float disparity map of the same size are needed");
    }
    if (boxPx < 5) throw InvalidInput("disparity floor: the box must be at least 5 px");
    cv::Mat left, right;
    greyLeft.convertTo(left, CV_32F);
    greyRight.convertTo(right, CV_32F);

    // Pixels the right eye sees too: per row, the nearest surface (largest disparity) landing on
    // each right column wins it; a left pixel behind that is hidden there (an occluded strip
    // beside a step, whose residuals say nothing about disparity noise).
    cv::Mat object = trueDisparity > 0;
    for (int y = 0; y < trueDisparity.rows; ++y) {
        const float* d = trueDisparity.ptr<float>(y);
        std::vector<float> nearest(static_cast<std::size_t>(trueDisparity.cols), -1.0f);
        for (int x = 0; x < trueDisparity.cols; ++x) {
            const int r = static_cast<int>(std::lround(x - d[x]));
            if (d[x] > 0 && r >= 0 && r < trueDisparity.cols) {
                nearest[static_cast<std::size_t>(r)] = std::max(nearest[static_cast<std::size_t>(r)], d[x]);
            }
        }
        auto* keep = object.ptr<std::uint8_t>(y);
        for (int x = 0; x < trueDisparity.cols; ++x) {
            const int r = static_cast<int>(std::lround(x - d[x]));
            if (keep[x] && (r < 0 || r >= trueDisparity.cols || d[x] < nearest[static_cast<std::size_t>(r)] - 0.5f)) {
                keep[x] = 0;
            }
        }
    }
    // One surface: no step of more than half a pixel between neighbours (a window across a step
    // mixes two shifts).
    cv::Mat largest, smallest;
    const cv::Mat square3 = cv::getStructuringElement(cv::MORPH_RECT, {3, 3});
    cv::dilate(trueDisparity, largest, square3);
    cv::erode(trueDisparity, smallest, square3);
    object &= (largest - smallest) < 0.5;
    // Three pixels in from every outline, hidden strip and step.
    cv::erode(object, object, cv::getStructuringElement(cv::MORPH_RECT, {7, 7}));

    cv::Mat mapX(left.size(), CV_32F), mapY(left.size(), CV_32F);
    for (int y = 0; y < left.rows; ++y)
        for (int x = 0; x < left.cols; ++x) {
            const float d = trueDisparity.at<float>(y, x);
            mapX.at<float>(y, x) = static_cast<float>(x) - (d > 0 ? d : 0.0f);
            mapY.at<float>(y, x) = static_cast<float>(y);
        }
    cv::Mat warped;
    // Cubic: linear interpolation blurs by a different amount at each fractional shift and would
    // add a bias of its own to the residuals.
    cv::remap(right, warped, mapX, mapY, cv::INTER_CUBIC, cv::BORDER_REPLICATE);

    DisparityFloor floor;
    floor.boxPx = boxPx;
    floor.objectPixels = cv::countNonZero(object);
    double residualSum = 0, residualSq = 0, gradientSq = 0, samples = 0;
    std::vector<double> shifts;
    for (int y0 = 0; y0 + boxPx <= left.rows; y0 += boxPx)
        for (int x0 = 0; x0 + boxPx <= left.cols; x0 += boxPx) {
            int n = 0;
            double se = 0, see = 0, sg = 0, seg = 0, sgg = 0;
            for (int y = y0; y < y0 + boxPx; ++y)
                for (int x = std::max(1, x0); x < std::min(x0 + boxPx, left.cols - 1); ++x) {
                    if (!object.at<std::uint8_t>(y, x)) continue;
                    const double e = left.at<float>(y, x) - warped.at<float>(y, x);
                    const double g = 0.5 * (warped.at<float>(y, x + 1) - warped.at<float>(y, x - 1));
                    ++n;
                    se += e;
                    see += e * e;
                    sg += g;
                    seg += e * g;
                    sgg += g * g;
                }
            if (n < 0.9 * boxPx * boxPx) continue;
            const double varG = sgg - sg * sg / n;
            if (varG <= 0) continue;
            // I_L = I_R(x - d - δ) ≈ warped - δ·g: the residual is -δ·g.
            shifts.push_back(-(seg - se * sg / n) / varG);
            residualSum += se;
            residualSq += see;
            gradientSq += sgg;
            samples += n;
        }
    floor.boxes = static_cast<int>(shifts.size());
    if (floor.boxes < 2) return floor;
    double mean = 0;
    for (double s : shifts) mean += s;
    mean /= floor.boxes;
    double var = 0;
    for (double s : shifts) var += (s - mean) * (s - mean);
    floor.boxMeanPx = mean;
    floor.boxSigmaPx = std::sqrt(var / (floor.boxes - 1));
    floor.residualSigma = std::sqrt(std::max(0.0, residualSq / samples - std::pow(residualSum / samples, 2)));
    floor.meanGradientSq = gradientSq / samples;
    return floor;
}

}  // namespace icewatch::synth
