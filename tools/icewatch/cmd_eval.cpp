// icewatch eval: match a pair (optionally with noise added) and score it against ground truth,
// the way the seed paper's tables and the Middlebury v2 table are made.
#include <iostream>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "core/common/error.hpp"
#include "core/stereo/evaluation.hpp"
#include "tools/icewatch/command.hpp"
#include "tools/icewatch/stereo_options.hpp"

namespace icewatch::cli {

namespace {

struct EvalOptions {
    StereoOptions stereo;
    std::string gt;
    double gtScale = 1.0;
    std::string mask;
    std::string noise = "none";
    std::uint64_t seed = 1;
    double threshold = 1.0;
    bool json = false;
    std::string badMap;
};

// The left image, darkened, with the evaluated pixels that count as bad in red.
cv::Mat badPixelPicture(const cv::Mat& left, const cv::Mat& disparity, const cv::Mat& gt, double gtScale,
                        const cv::Mat& mask, double threshold) {
    cv::Mat picture = left * 0.5;
    for (int y = 0; y < picture.rows; ++y)
        for (int x = 0; x < picture.cols; ++x) {
            const std::uint8_t g = gt.at<std::uint8_t>(y, x);
            if (g == 0 || (!mask.empty() && mask.at<std::uint8_t>(y, x) != 255)) continue;
            const float d = disparity.at<float>(y, x);
            if (d < 0.0f || std::abs(d - g / gtScale) > threshold) picture.at<cv::Vec3b>(y, x) = {0, 0, 255};
        }
    return picture;
}

}  // namespace

void addEvalCommand(CLI::App& app, const GlobalOptions& /*global*/, RunFunction& run) {
    CLI::App* command = app.add_subcommand("eval", "score a method's disparity against ground truth");
    auto o = std::make_shared<EvalOptions>();
    addStereoOptions(*command, o->stereo);
    command->add_option("--gt", o->gt, "ground-truth disparity image (8-bit, disparity x scale, 0 = unknown)")->required();
    command->add_option("--gt-scale", o->gtScale, "ground-truth scale")->required()->check(CLI::PositiveNumber);
    command->add_option("--mask", o->mask, "evaluate only where this 8-bit mask is 255 (e.g. nonocc.png)");
    command->add_option("--noise", o->noise, "none, saltpepper:PERCENT or gauss:SIGMA");
    command->add_option("--seed", o->seed, "noise seed (the right image uses the next one)");
    command->add_option("--threshold", o->threshold, "bad when |d - gt| exceeds this (px)")->check(CLI::NonNegativeNumber);
    command->add_flag("--json", o->json, "print one JSON object");
    command->add_option("--bad-map", o->badMap, "write a picture of the bad pixels (PNG)");
    command->callback([&run, o] {
        run = [o] {
            const stereo::NoiseSpec noise = stereo::parseNoise(o->noise);
            cv::Mat left = readImage(o->stereo.left, cv::IMREAD_COLOR);
            cv::Mat right = readImage(o->stereo.right, cv::IMREAD_COLOR);
            const cv::Mat gt = readImage(o->gt, cv::IMREAD_GRAYSCALE);
            const cv::Mat mask = o->mask.empty() ? cv::Mat() : readImage(o->mask, cv::IMREAD_GRAYSCALE);
            stereo::addNoise(left, noise, o->seed);
            stereo::addNoise(right, noise, o->seed + 1);
            stereo::Matcher matcher(stereo::parseMethod(o->stereo.method), stereoParameters(o->stereo));
            const double start = nowMs();
            const cv::Mat disparity = matcher.compute(left, right, o->stereo.range());
            const double matchMs = nowMs() - start;
            const stereo::DisparityScore score = stereo::scoreDisparity(disparity, gt, o->gtScale, mask, o->threshold);
            if (!o->badMap.empty() &&
                !cv::imwrite(o->badMap, badPixelPicture(left, disparity, gt, o->gtScale, mask, o->threshold))) {
                throw Error(kExitCantCreate, o->badMap + ": cannot write the picture");
            }
            const nlohmann::json result{{"bad_percent", score.badPercent},   {"valid_percent", score.validPercent},
                                        {"match_ms", matchMs},               {"method", o->stereo.method},
                                        {"noise", noise.text},               {"seed", o->seed},
                                        {"threshold", o->threshold},         {"evaluated_pixels", score.evaluated},
                                        {"min_disp", o->stereo.minDisparity}, {"max_disp", o->stereo.maxDisparity}};
            if (o->json) {
                std::cout << result.dump() << "\n";
            } else {
                std::cout << o->stereo.method << ": " << score.badPercent << " % bad (> " << o->threshold << " px), "
                          << score.validPercent << " % valid, " << matchMs << " ms, noise " << noise.text << "\n";
            }
            return 0;
        };
    });
}

}  // namespace icewatch::cli
