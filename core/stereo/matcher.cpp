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

void validateInput(const cv::Mat& left, const cv::Mat& right, DisparityRange range) {
    if (left.empty() || right.empty()) {
        throw InvalidInput("stereo pair: an image is empty");
    }
    if (left.size() != right.size()) {
        throw InvalidInput("stereo pair: sizes differ (left " + std::to_string(left.cols) + "x" +
                           std::to_string(left.rows) + ", right " + std::to_string(right.cols) + "x" +
                           std::to_string(right.rows) + ")");
    }
    const int type = left.type();
    if (type != right.type() || (type != CV_8UC3 && type != CV_8UC1 && type != CV_32FC1)) {
        throw InvalidInput("stereo pair: both images must be of the same type, 8-bit BGR, 8-bit grey or float grey");
    }
    if (type == CV_32FC1 && (!cv::checkRange(left) || !cv::checkRange(right))) {
        throw InvalidInput("stereo pair: a float image holds a value that is not finite (NaN or infinity)");
    }
    const std::string band = "disparity band [" + std::to_string(range.min) + ", " + std::to_string(range.max) + ")";
    if (range.min < 0) throw InvalidInput(band + ": the minimum must not be negative");
    if (range.width() < kMinDisparityBand) {
        throw InvalidInput(band + ": needs at least " + std::to_string(kMinDisparityBand) + " disparities");
    }
    if (range.max >= left.cols) {
        throw InvalidInput(band + ": max disparity must be below the image width " + std::to_string(left.cols));
    }
}

cv::Mat roundedToEightBits(const cv::Mat& image) {
    if (image.depth() == CV_8U) return image;
    cv::Mat rounded;
    image.convertTo(rounded, CV_8U);  // to nearest, saturated at 0 and 255
    return rounded;
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
    return compute(left, right, DisparityRange{0, maxDisparity});
}

cv::Mat Matcher::compute(const cv::Mat& left, const cv::Mat& right, DisparityRange range) {
    validateInput(left, right, range);
    switch (impl_->method) {
        case Method::Sgbm:
            // OpenCV's SGBM takes 8-bit images only: a float average is matched on its rounding.
            return impl_->sgbm.compute(roundedToEightBits(left), roundedToEightBits(right), range);
        case Method::Paper:
        case Method::AdCensus:
            return impl_->census.compute(left, right, range);
    }
    throw Error(kExitSoftware, "stereo method \"" + methodName(impl_->method) + "\" is not available");
}

void Matcher::releaseBuffers() {
    impl_->sgbm.releaseBuffers();
    impl_->census.releaseBuffers();
}

void Matcher::setKeepBuffers(bool keep) {
    impl_->sgbm.setKeepBuffers(keep);
    impl_->census.setKeepBuffers(keep);
}

Method Matcher::method() const { return impl_->method; }
const Parameters& Matcher::parameters() const { return impl_->parameters; }

}  // namespace icewatch::stereo
