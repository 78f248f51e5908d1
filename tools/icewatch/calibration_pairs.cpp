// The pairs of a chessboard session, read from where a person has them: a recording of the
// side-by-side camera or OpenCV's image-list file. Images are loaded one pair at a time.
#include "tools/icewatch/calibration_pairs.hpp"

#include <algorithm>
#include <fstream>
#include <iterator>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/common/error.hpp"

namespace icewatch::cli {

namespace fs = std::filesystem;

namespace {

std::string lower(std::string text) {
    std::transform(text.begin(), text.end(), text.begin(), [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
    return text;
}

// Raw YUYV 4:2:2 as the camera sent it: 2 bytes a pixel, size from recording.json.
cv::Mat readYuyv(const fs::path& path, cv::Size size) {
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        throw Error(kExitNoInput, path.string() + ": cannot read frame");
    }
    std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const size_t expected = static_cast<size_t>(size.area()) * 2;
    if (bytes.size() != expected) {
        throw Error(kExitDataErr, path.string() + ": " + std::to_string(bytes.size()) + " bytes, a " +
                                      std::to_string(size.width) + "x" + std::to_string(size.height) +
                                      " YUYV frame has " + std::to_string(expected));
    }
    const cv::Mat yuyv(size, CV_8UC2, bytes.data());
    cv::Mat bgr;
    cv::cvtColor(yuyv, bgr, cv::COLOR_YUV2BGR_YUYV);
    return bgr;
}

// Width and height of a recording's frames, needed only for raw frames.
cv::Size recordingFrameSize(const fs::path& dir) {
    const fs::path file = dir / "recording.json";
    std::ifstream in(file);
    nlohmann::json meta;
    try {
        meta = nlohmann::json::parse(in);
    } catch (const nlohmann::json::exception& e) {
        throw Error(kExitDataErr, file.string() + ": not valid JSON: " + e.what());
    }
    if (!meta.is_object() || !meta.contains("width") || !meta.contains("height") || !meta["width"].is_number_integer() ||
        !meta["height"].is_number_integer()) {
        throw Error(kExitDataErr, file.string() + ": integer width and height are needed to decode raw YUYV frames");
    }
    return {meta["width"].get<int>(), meta["height"].get<int>()};
}

StereoPair split(const cv::Mat& frame, const fs::path& path) {
    try {
        return splitSideBySide(frame);
    } catch (const Error& e) {
        throw Error(kExitDataErr, path.string() + ": " + e.what());
    }
}

void forEachFrameInDirectory(const fs::path& dir, int step, const PairVisitor& visit) {
    std::vector<fs::path> frames;
    bool raw = false;
    for (const fs::directory_entry& entry : fs::directory_iterator(dir)) {
        const std::string ext = lower(entry.path().extension().string());
        if (!entry.is_regular_file()) {
            continue;
        }
        if (ext == ".jpg" || ext == ".jpeg" || ext == ".png") {
            frames.push_back(entry.path());
        } else if (ext == ".yuyv") {
            frames.push_back(entry.path());
            raw = true;
        }
    }
    if (frames.empty()) {
        throw Error(kExitNoInput, dir.string() + ": no side-by-side frames (.jpg, .png or .yuyv) in the directory");
    }
    std::sort(frames.begin(), frames.end());
    const cv::Size rawSize = raw ? recordingFrameSize(dir) : cv::Size();
    for (size_t i = 0; i < frames.size(); i += static_cast<size_t>(step)) {
        const fs::path& path = frames[i];
        const cv::Mat frame = lower(path.extension().string()) == ".yuyv" ? readYuyv(path, rawSize) : readImage(path);
        visit(path.filename().string(), split(frame, path));
    }
}

void forEachPairInImageList(const fs::path& list, int step, const PairVisitor& visit) {
    std::vector<std::string> names;
    try {
        cv::FileStorage storage(list.string(), cv::FileStorage::READ);
        if (!storage.isOpened()) {
            throw Error(kExitDataErr, list.string() + ": not a readable OpenCV image list");
        }
        cv::FileNode node = storage["imagelist"];
        if (node.empty()) {
            node = storage.getFirstTopLevelNode();
        }
        if (!node.isSeq()) {
            throw Error(kExitDataErr, list.string() + ": must hold a list of image names (like <imagelist>)");
        }
        for (const cv::FileNode& item : node) {
            if (!item.isString()) {
                throw Error(kExitDataErr, list.string() + ": every entry of the image list must be a file name");
            }
            names.push_back(static_cast<std::string>(item));
        }
    } catch (const cv::Exception& e) {
        throw Error(kExitDataErr, list.string() + ": not a readable OpenCV image list (" + e.err + ")");
    }
    if (names.empty() || names.size() % 2 != 0) {
        throw Error(kExitDataErr, list.string() + ": the image list must alternate left and right images, got " +
                                      std::to_string(names.size()) + " names");
    }
    const fs::path base = list.parent_path();
    for (size_t i = 0; i < names.size(); i += 2 * static_cast<size_t>(step)) {
        const fs::path leftPath = fs::path(names[i]).is_absolute() ? fs::path(names[i]) : base / names[i];
        const fs::path rightPath = fs::path(names[i + 1]).is_absolute() ? fs::path(names[i + 1]) : base / names[i + 1];
        StereoPair pair{readImage(leftPath), readImage(rightPath)};
        if (pair.left.size() != pair.right.size()) {
            throw Error(kExitDataErr, rightPath.string() + ": size differs from its left image " + leftPath.string());
        }
        visit(fs::path(names[i]).filename().string() + "+" + fs::path(names[i + 1]).filename().string(), pair);
    }
}

}  // namespace

cv::Mat readImage(const fs::path& path) {
    if (!fs::is_regular_file(path)) {
        throw Error(kExitNoInput, path.string() + ": image not found");
    }
    cv::Mat image;
    try {
        image = cv::imread(path.string(), cv::IMREAD_COLOR);
    } catch (const cv::Exception& e) {
        throw Error(kExitDataErr, path.string() + ": not a readable image (" + e.err + ")");
    }
    if (image.empty()) {
        throw Error(kExitDataErr, path.string() + ": not a readable image");
    }
    return image;
}

void forEachCalibrationPair(const fs::path& source, int step, const PairVisitor& visit) {
    if (step < 1) {
        throw Error(kExitUsage, "the pair step must be at least 1");
    }
    if (fs::is_directory(source)) {
        forEachFrameInDirectory(source, step, visit);
    } else if (fs::is_regular_file(source)) {
        forEachPairInImageList(source, step, visit);
    } else {
        throw Error(kExitNoInput, source.string() + ": no such directory or image list");
    }
}

}  // namespace icewatch::cli
