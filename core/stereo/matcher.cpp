// The public matcher: picks a method and owns its per-image-size scratch.
#include "core/stereo/matcher.hpp"

#include <opencv2/calib3d.hpp>

#include "core/common/error.hpp"
#include "core/stereo/census_matcher.hpp"
#include "core/stereo/sgbm_matcher.hpp"

namespace icewatch::stereo {

Method parseMethod(std::string_view name) {
    if (name == "paper") return Method::Paper;
    if (name == "adcensus") return Method::AdCensus;
    if (name == "sgbm") return Method::Sgbm;
    throw InvalidInput("unknown stereo method \"" + std::string(name) + "\" (paper, adcensus, sgbm)");
}

std::string methodName(Method method) {
    switch (method) {
        case Method::Paper: return "paper";
        case Method::AdCensus: return "adcensus";
        case Method::Sgbm: return "sgbm";
    }
    return "unknown";
}

void validateInput(const cv::Mat& left, const cv::Mat& right, int maxDisparity) {
    if (left.empty() || right.empty()) {
        throw InvalidInput("stereo pair: an image is empty");
    }
    if (left.size() != right.size()) {
        throw InvalidInput("stereo pair: sizes differ (left " + std::to_string(left.cols) + "x" +
                           std::to_string(left.rows) + ", right " + std::to_string(right.cols) + "x" +
                           std::to_string(right.rows) + ")");
    }
    if (left.type() != right.type() || (left.type() != CV_8UC3 && left.type() != CV_8UC1)) {
        throw InvalidInput("stereo pair: both images must be 8-bit BGR or 8-bit grey of the same type");
    }
    if (maxDisparity <= 0 || maxDisparity >= left.cols) {
        throw InvalidInput("max disparity " + std::to_string(maxDisparity) + " must be in 1.." +
                           std::to_string(left.cols - 1) + " for an image " + std::to_string(left.cols) +
                           " wide");
    }
}

struct Matcher::Impl {
    Method method;
    Parameters parameters;
    SgbmMatcher sgbm;
    CensusMatcher census;
};

Matcher::Matcher(Method method, const Parameters& parameters)
    : impl_(std::make_unique<Impl>(Impl{method, parameters, SgbmMatcher(parameters), CensusMatcher(method, parameters)})) {}

Matcher::~Matcher() = default;
Matcher::Matcher(Matcher&&) noexcept = default;
Matcher& Matcher::operator=(Matcher&&) noexcept = default;

cv::Mat Matcher::compute(const cv::Mat& left, const cv::Mat& right, int maxDisparity) {
    validateInput(left, right, maxDisparity);
    switch (impl_->method) {
        case Method::Sgbm:
            return impl_->sgbm.compute(left, right, maxDisparity);
        case Method::Paper:
        case Method::AdCensus:
            return impl_->census.compute(left, right, maxDisparity);
    }
    throw Error(kExitSoftware, "stereo method \"" + methodName(impl_->method) + "\" is not available");
}

Method Matcher::method() const { return impl_->method; }
const Parameters& Matcher::parameters() const { return impl_->parameters; }

}  // namespace icewatch::stereo
