// Disparity files: PFM for programs, a false-colour PNG for people.
#include "core/stereo/disparity_io.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>

#include "core/common/error.hpp"
#include "core/pictures/colour_scale.hpp"
#include "core/stereo/matcher.hpp"

namespace icewatch::stereo {

void writePfm(const std::filesystem::path& path, const cv::Mat& disparity) {
    if (disparity.type() != CV_32FC1) throw InvalidInput("PFM: only one-channel float images can be written");
    std::ofstream out(path, std::ios::binary);
    if (!out) throw Error(kExitCantCreate, path.string() + ": cannot create the PFM file");
    // Negative scale = little endian.
    out << "Pf\n" << disparity.cols << " " << disparity.rows << "\n-1.0\n";
    std::vector<float> row(static_cast<std::size_t>(disparity.cols));
    for (int y = disparity.rows - 1; y >= 0; --y) {
        const auto* d = disparity.ptr<float>(y);
        for (int x = 0; x < disparity.cols; ++x) {
            row[static_cast<std::size_t>(x)] = d[x] < 0.0f ? std::numeric_limits<float>::infinity() : d[x];
        }
        static_assert(std::endian::native == std::endian::little, "PFM writer assumes a little-endian host");
        out.write(reinterpret_cast<const char*>(row.data()), static_cast<std::streamsize>(row.size() * sizeof(float)));
    }
    out.close();
    if (!out) throw Error(kExitIoErr, path.string() + ": error while writing the PFM file");
}

cv::Mat readPfm(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(kExitNoInput, path.string() + ": cannot open the PFM file");
    std::string magic;
    int width = 0, height = 0;
    double scale = 0.0;
    in >> magic >> width >> height >> scale;
    if (!in || magic != "Pf" || width <= 0 || height <= 0 || width > 1 << 16 || height > 1 << 16 || scale == 0.0) {
        throw Error(kExitDataErr, path.string() + ": not a one-channel PFM file (expected \"Pf\", size, scale)");
    }
    in.get();  // the single whitespace after the scale
    cv::Mat disparity(height, width, CV_32FC1);
    std::vector<std::uint32_t> row(static_cast<std::size_t>(width));
    for (int y = height - 1; y >= 0; --y) {
        in.read(reinterpret_cast<char*>(row.data()), static_cast<std::streamsize>(row.size() * sizeof(float)));
        if (!in) throw Error(kExitDataErr, path.string() + ": PFM file is truncated");
        auto* d = disparity.ptr<float>(y);
        for (int x = 0; x < width; ++x) {
            std::uint32_t bits = row[static_cast<std::size_t>(x)];
            if (scale > 0.0) bits = __builtin_bswap32(bits);  // big-endian file
            float value;
            std::memcpy(&value, &bits, sizeof value);
            d[x] = std::isfinite(value) ? value : kInvalidDisparity;
        }
    }
    return disparity;
}

cv::Mat colorizeDisparity(const cv::Mat& disparity, int maxDisparity) {
    if (disparity.type() != CV_32FC1) throw InvalidInput("colour map: disparity must be 32-bit float");
    cv::Mat values = disparity.clone();
    values.setTo(std::numeric_limits<float>::quiet_NaN(), disparity < 0);
    return pictures::falseColour(values, {0.0, static_cast<double>(std::max(1, maxDisparity)), "px", "disparity"});
}

}  // namespace icewatch::stereo
