// icewatch bench: the paper's matcher against OpenCV StereoSGBM (3-way) on the same pair in the
// same process, alternating runs so both see the same machine load, medians of N runs each.
#include <algorithm>
#include <iostream>

#include <nlohmann/json.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>

#include "tools/icewatch/command.hpp"
#include "tools/icewatch/stereo_options.hpp"

namespace icewatch::cli {

namespace {

double median(std::vector<double> values) {
    std::sort(values.begin(), values.end());
    const std::size_t n = values.size();
    return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

double timeOnce(stereo::Matcher& matcher, const cv::Mat& left, const cv::Mat& right, stereo::DisparityRange range) {
    const double start = nowMs();
    const cv::Mat disparity = matcher.compute(left, right, range);
    return nowMs() - start;
}

}  // namespace

void addBenchCommand(CLI::App& app, const GlobalOptions& /*global*/, RunFunction& run) {
    CLI::App* command = app.add_subcommand("bench", "time the paper method against OpenCV StereoSGBM 3-way");
    auto options = std::make_shared<StereoOptions>();
    auto repeat = std::make_shared<int>(5);
    auto json = std::make_shared<bool>(false);
    addStereoOptions(*command, *options, /*withMethod=*/false);
    command->add_option("--repeat", *repeat, "runs of each method")->check(CLI::Range(1, 1000));
    command->add_flag("--json", *json, "print one JSON object");
    command->callback([&run, options, repeat, json] {
        run = [options, repeat, json] {
            const cv::Mat left = readImage(options->left, cv::IMREAD_COLOR);
            const cv::Mat right = readImage(options->right, cv::IMREAD_COLOR);
            const stereo::Parameters parameters = stereoParameters(*options);
            stereo::Matcher paper(stereo::Method::Paper, parameters);
            stereo::Matcher sgbm(stereo::Method::Sgbm, parameters);
            // One untimed run each: buffers are allocated once per image size, as in service.
            timeOnce(paper, left, right, options->range());
            timeOnce(sgbm, left, right, options->range());
            std::vector<double> paperMs, sgbmMs;
            for (int i = 0; i < *repeat; ++i) {
                paperMs.push_back(timeOnce(paper, left, right, options->range()));
                sgbmMs.push_back(timeOnce(sgbm, left, right, options->range()));
            }
            const double p = median(paperMs), s = median(sgbmMs);
            const nlohmann::json result{{"paper_ms", p},         {"sgbm_ms", s},
                                        {"ratio", p / s},        {"repeat", *repeat},
                                        {"threads", cv::getNumThreads()},
                                        {"width", left.cols},    {"height", left.rows},
                                        {"min_disp", options->minDisparity}, {"max_disp", options->maxDisparity}};
            if (*json) {
                std::cout << result.dump() << "\n";
            } else {
                std::cout << "paper " << p << " ms, sgbm " << s << " ms, ratio " << p / s << "\n";
            }
            return 0;
        };
    });
}

}  // namespace icewatch::cli
