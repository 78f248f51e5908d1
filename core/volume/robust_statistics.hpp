// The robust statistics the volume stages share: medians and the median-absolute spreads that stand
// for a σ where part of the values may be ice, a mismatch or another surface.
//
// A median here is the element at size/2 once ordered: the upper of the two middles for an even
// count, never their mean, so it is always one of the values (a ratio of 1 stays exactly 1, a
// height on the grid stays on it). The stages were tuned with that convention; keep it.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

namespace icewatch::volume {

// 1.4826 times a median absolute value is the σ of a normal distribution.
inline constexpr double kMadToSigma = 1.4826;

// The median of `values`, which must not be empty (the caller knows what none should mean).
template <class T>
T median(std::vector<T> values) {
    CV_Assert(!values.empty());
    const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
    std::nth_element(values.begin(), middle, values.end());
    return *middle;
}

// The σ of values centred on zero by their nature (differences, residuals from a fit): 1.4826 times
// their median absolute value; 0 for none.
template <class T>
double spreadAboutZero(std::vector<T> values) {
    if (values.empty()) return 0.0;
    for (T& v : values) v = std::abs(v);
    return kMadToSigma * median(std::move(values));
}

// The σ of values about `centre`: 1.4826 times their median absolute deviation from it; 0 for none.
template <class T>
double spreadAbout(std::vector<T> values, T centre) {
    if (values.empty()) return 0.0;
    for (T& v : values) v = std::abs(v - centre);
    return kMadToSigma * median(std::move(values));
}

// The σ of values about their own median; 0 for none.
template <class T>
double spreadAboutMedian(std::vector<T> values) {
    if (values.empty()) return 0.0;
    const T centre = median(values);
    return spreadAbout(std::move(values), centre);
}

}  // namespace icewatch::volume
