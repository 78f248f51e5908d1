#include <algorithm>
#include <initializer_list>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/stereo/stages.hpp"
#include "tests/core/stereo/stereo_test_images.hpp"
#include "tests/support/test_paths.hpp"

namespace icewatch::stereo::detail {
namespace {

// The edge and corner bits by their definition: OpenCV's Canny on the 3x3 Sobel derivatives, and
// Harris from OpenCV's float box filter over the derivatives' products, response in double.
cv::Mat edgeCornerBitsByDefinition(const cv::Mat& grey, const Parameters& parameters) {
    cv::Mat dx, dy;
    cv::Sobel(grey, dx, CV_16S, 1, 0, 3, 1.0, 0.0, cv::BORDER_REPLICATE);
    cv::Sobel(grey, dy, CV_16S, 0, 1, 3, 1.0, 0.0, cv::BORDER_REPLICATE);
    cv::Mat edges;
    cv::Canny(dx, dy, edges, parameters.cannyLowThreshold, parameters.cannyHighThreshold, true);
    cv::Mat fx, fy, xx, xy, yy;
    dx.convertTo(fx, CV_32F);
    dy.convertTo(fy, CV_32F);
    cv::boxFilter(fx.mul(fx), xx, CV_32F, {3, 3}, {-1, -1}, false, cv::BORDER_REPLICATE);
    cv::boxFilter(fx.mul(fy), xy, CV_32F, {3, 3}, {-1, -1}, false, cv::BORDER_REPLICATE);
    cv::boxFilter(fy.mul(fy), yy, CV_32F, {3, 3}, {-1, -1}, false, cv::BORDER_REPLICATE);
    cv::Mat response(grey.size(), CV_64F);
    double maxResponse = 0.0;
    for (int y = 0; y < grey.rows; ++y)
        for (int x = 0; x < grey.cols; ++x) {
            const double a = xx.at<float>(y, x), b = xy.at<float>(y, x), c = yy.at<float>(y, x);
            response.at<double>(y, x) = a * c - b * b - 0.04 * (a + c) * (a + c);
            maxResponse = std::max(maxResponse, response.at<double>(y, x));
        }
    cv::Mat bits(grey.size(), CV_8UC1);
    for (int y = 0; y < grey.rows; ++y)
        for (int x = 0; x < grey.cols; ++x) {
            const bool corner = maxResponse > 0.0 && response.at<double>(y, x) > parameters.harrisThreshold * maxResponse;
            bits.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>((edges.at<std::uint8_t>(y, x) ? 2 : 0) + (corner ? 1 : 0));
        }
    return bits;
}

// Grey test images: each size as random noise and blurred by sigma `blur`, then the left image of
// a Middlebury scene.
std::vector<cv::Mat> greyImages(std::initializer_list<std::pair<int, int>> sizes, int seed, double blur,
                                const char* scene) {
    std::vector<cv::Mat> images;
    for (const auto& [width, height] : sizes) {
        cv::Mat grey = test::randomImage(width, height, CV_8UC1, seed), smooth;
        cv::GaussianBlur(grey, smooth, cv::Size(0, 0), blur);
        images.push_back(grey);
        images.push_back(smooth);
    }
    images.push_back(
        cv::imread((icewatch::test::sharedData() / "middlebury" / scene / "left.png").string(), cv::IMREAD_GRAYSCALE));
    return images;
}

TEST(CannyEdges, EqualOpenCVsCanny) {
    // Random and smooth images (gradients in every direction, long weak edges for the hysteresis
    // to follow), a real one, sizes that leave a scalar tail, thresholds swapped, zero and huge.
    const std::vector<cv::Mat> images = greyImages({{631, 479}, {37, 23}, {3, 1}, {1, 4}}, 5, 2.0, "teddy");
    ASSERT_FALSE(images.back().empty());
    for (const cv::Mat& grey : images) {
        cv::Mat dx, dy;
        sobel16(grey, dx, dy);
        for (const auto& [low, high] : {std::pair{30.0, 100.0}, std::pair{100.0, 30.0}, std::pair{0.0, 10.0},
                                         std::pair{5.0, 5.0}, std::pair{40000.0, 50000.0}}) {
            cv::Mat fast, plain;
            cannyEdges(dx, dy, low, high, fast);
            cv::Canny(dx, dy, plain, low, high, true);
            EXPECT_EQ(cv::countNonZero(fast != plain), 0) << grey.cols << "x" << grey.rows << " " << low << "/" << high;
        }
    }
    // The smooth large image has weak edges that only the hysteresis keeps.
    cv::Mat dx, dy, strongOnly, both;
    sobel16(images[1], dx, dy);
    cannyEdges(dx, dy, 60.0, 60.0, strongOnly);
    cannyEdges(dx, dy, 10.0, 60.0, both);
    EXPECT_GT(cv::countNonZero(both), cv::countNonZero(strongOnly));
}

int nibbleAt(const std::uint64_t* words, int k) { return static_cast<int>((words[k >> 4] >> (4 * (k & 15))) & 0xF); }

TEST(EdgeCornerBits, EqualTheDefinition) {
    const std::vector<cv::Mat> images = greyImages({{631, 479}, {17, 9}, {1, 5}}, 21, 1.5, "cones");
    ASSERT_FALSE(images.back().empty());
    for (const double threshold : {0.001, 0.05}) {
        Parameters parameters;
        parameters.harrisThreshold = threshold;
        for (const cv::Mat& grey : images) {
            const cv::Mat fast = edgeCornerBits(grey, parameters), plain = edgeCornerBitsByDefinition(grey, parameters);
            EXPECT_EQ(cv::countNonZero(fast != plain), 0) << grey.cols << "x" << grey.rows << ", " << threshold;
            // Corners occur, except on a single column, where there is no horizontal derivative.
            if (grey.cols > 1) {
                EXPECT_GT(cv::countNonZero(plain & 1), 0) << grey.cols << "x" << grey.rows;
            }
        }
    }
}

// Per channel: sqrt(Sobel_x² + Sobel_y²) / 8 in grey levels per pixel, in kGradientSteps steps,
// rounded, saturated at 255 (steep edges of a drawn image reach it).
TEST(ChannelGradientMagnitudes, EqualTheDefinition) {
    std::vector<cv::Mat> images;
    for (const auto& [width, height] : {std::pair{631, 479}, std::pair{17, 9}, std::pair{3, 2}}) {
        images.push_back(test::randomImage(width, height, CV_8UC3, 22));
    }
    cv::Mat blocks(40, 57, CV_8UC3, cv::Scalar(0, 0, 0));
    cv::rectangle(blocks, {10, 10, 20, 15}, cv::Scalar(255, 128, 3), cv::FILLED);
    images.push_back(blocks);
    for (const cv::Mat& bgr : images) {
        cv::Mat dx, dy;
        cv::Sobel(bgr, dx, CV_32F, 1, 0, 3, 1.0 / 8.0, 0.0, cv::BORDER_REPLICATE);
        cv::Sobel(bgr, dy, CV_32F, 0, 1, 3, 1.0 / 8.0, 0.0, cv::BORDER_REPLICATE);
        const cv::Mat fast = channelGradientMagnitudes(bgr);
        ASSERT_EQ(fast.type(), CV_8UC3);
        int differ = 0, saturated = 0;
        for (int y = 0; y < bgr.rows; ++y)
            for (int x = 0; x < bgr.cols * 3; ++x) {
                const float gx = dx.ptr<float>(y)[x], gy = dy.ptr<float>(y)[x];
                const auto expected = cv::saturate_cast<std::uint8_t>(std::sqrt(gx * gx + gy * gy) * kGradientSteps);
                differ += fast.ptr<std::uint8_t>(y)[x] != expected;
                saturated += expected == 255;
            }
        EXPECT_EQ(differ, 0) << bgr.cols << "x" << bgr.rows;
        if (bgr.cols == 57) {
            EXPECT_GT(saturated, 0);
        }
    }
}

TEST(ImprovedCensus, HandComputedCodeWithTrimmedMeanAndAlphaBand) {
    // A 9x9 image, all 100 except a few chosen pixels around the centre (4, 4). 7x7 window of the
    // centre: 49 values. Put one 255 (the maximum, dropped) and one 0 (the minimum, dropped), a 103
    // and a 97 next to the centre; the trimmed sum is 45*100 + 103 + 97 = 4700 over 47 values:
    // ref = 100. With alpha = 2: 103 > 102 codes 10, 97 < 98 codes 01, 101 and 99 (inside the band)
    // code 00, and the maximum and minimum themselves still code 10 and 01.
    cv::Mat grey(9, 9, CV_8UC1, cv::Scalar(100));
    grey.at<std::uint8_t>(1, 1) = 255;  // window offset (-3, -3): neighbour 0
    grey.at<std::uint8_t>(7, 7) = 0;    // offset (3, 3): the last neighbour, 47
    grey.at<std::uint8_t>(4, 5) = 103;  // offset (0, 1): neighbour 24
    grey.at<std::uint8_t>(4, 3) = 97;   // offset (0, -1): neighbour 23
    cv::Mat ec = cv::Mat::zeros(9, 9, CV_8UC1);
    ec.at<std::uint8_t>(3, 4) = 2;  // an edge at offset (-1, 0): neighbour 17
    ec.at<std::uint8_t>(5, 4) = 1;  // a corner at offset (1, 0): neighbour 30
    cv::Mat window7 = cv::Mat::ones(9, 9, CV_8UC1);
    CensusImage census;
    improvedCensus(grey, ec, 2, window7, census);
    const std::uint64_t* code = census.at(4, 4) + kCensus7Offset;
    EXPECT_EQ(nibbleAt(code, 0), 0b1000);
    EXPECT_EQ(nibbleAt(code, 47), 0b0100);
    EXPECT_EQ(nibbleAt(code, 24), 0b1000);
    EXPECT_EQ(nibbleAt(code, 23), 0b0100);
    EXPECT_EQ(nibbleAt(code, 17), 0b0010);
    EXPECT_EQ(nibbleAt(code, 30), 0b0001);
    for (int k : {1, 2, 10, 22, 25, 40, 46}) EXPECT_EQ(nibbleAt(code, k), 0) << k;

    // Trimmed sum 45*100 + 101 + 98 = 4699: ref 99.98, band (97.98, 101.98): both code 00.
    grey.at<std::uint8_t>(4, 5) = 101;
    grey.at<std::uint8_t>(4, 3) = 98;
    improvedCensus(grey, ec, 2, window7, census);
    code = census.at(4, 4) + kCensus7Offset;
    EXPECT_EQ(nibbleAt(code, 24), 0);
    EXPECT_EQ(nibbleAt(code, 23), 0);
    // Alpha 0: the same pixels leave the band.
    improvedCensus(grey, ec, 0, window7, census);
    code = census.at(4, 4) + kCensus7Offset;
    EXPECT_EQ(nibbleAt(code, 24), 0b1000);
    EXPECT_EQ(nibbleAt(code, 23), 0b0100);
}

TEST(ImprovedCensus, WindowFollowsTheGradient) {
    // Left half flat, a sharp vertical edge in the middle: the edge pixels get 7x7, flat ones 9x9.
    cv::Mat grey(20, 40, CV_8UC1, cv::Scalar(50));
    grey(cv::Rect(20, 0, 20, 20)).setTo(200);
    const cv::Mat mask = censusWindowMask(grey, 6.0);
    EXPECT_EQ(mask.at<std::uint8_t>(10, 19), 1);
    EXPECT_EQ(mask.at<std::uint8_t>(10, 20), 1);
    EXPECT_EQ(mask.at<std::uint8_t>(10, 5), 0);
    EXPECT_EQ(mask.at<std::uint8_t>(10, 35), 0);
    // A pixel with the 9x9 window codes only its 9x9 part; the right image gets both codes.
    const cv::Mat ec = cv::Mat::zeros(grey.size(), CV_8UC1);
    CensusImage left, right;
    improvedCensus(grey, ec, 2, mask, left);
    improvedCensus(grey, ec, 2, cv::Mat(), right);
    // The flat pixel 4 columns left of the edge sees the bright side only in its 9x9 window.
    const std::uint64_t* flat = left.at(16, 10);
    for (int w = 0; w < kCensus7Words; ++w) EXPECT_EQ(flat[kCensus7Offset + w], 0u);
    int brighter = 0;
    for (int k = 0; k < 80; ++k) brighter += nibbleAt(flat + kCensus9Offset, k) == 0b1000;
    EXPECT_EQ(brighter, 9);  // column x = 20, 9 rows
    EXPECT_NE(right.at(16, 10)[kCensus9Offset], 0u);
    // Its 7x7 window (x = 13..19) is all 50: every neighbour inside the band.
    EXPECT_EQ(right.at(16, 10)[kCensus7Offset], 0u);
}

TEST(ImprovedCensus, OptimisedEqualsReference) {
    const cv::Mat grey = test::randomImage(631, 479, CV_8UC1, 7);
    cv::Mat ec(grey.size(), CV_8UC1);
    cv::randu(ec, 0, 4);
    const cv::Mat mask = censusWindowMask(grey, 6.0);
    for (const cv::Mat& m : {mask, cv::Mat()}) {
        CensusImage fast, plain;
        improvedCensus(grey, ec, 2, m, fast);
        improvedCensusReference(grey, ec, 2, m, plain);
        EXPECT_EQ(fast.data, plain.data);
    }
}

// The encoder codes 16 or 32 pixels at once (by vector width) and skips a window no pixel of a
// chunk wants: widths below, at and around both chunk sizes, masks that want one window
// everywhere, alpha at 0 and beyond the grey range, and images whose thresholds reach 0 and 255.
TEST(ImprovedCensus, OptimisedEqualsReferenceAtChunkEdges) {
    const cv::Size sizes[] = {{1, 1}, {5, 3}, {15, 4}, {16, 6}, {17, 5}, {31, 9}, {32, 7}, {33, 8}, {64, 5}, {97, 11}};
    int seed = 11;
    for (const cv::Size size : sizes) {
        cv::Mat smooth = test::randomImage(size.width, size.height, CV_8UC1, ++seed);
        cv::Mat binary(size, CV_8UC1);
        cv::randu(binary, 0, 2);
        binary *= 255;
        cv::Mat dark = cv::Mat::zeros(size, CV_8UC1), bright(size, CV_8UC1, cv::Scalar(255));
        cv::Mat ec(size, CV_8UC1);
        cv::randu(ec, 0, 4);
        cv::Mat mixed(size, CV_8UC1);
        cv::randu(mixed, 0, 2);
        const cv::Mat masks[] = {cv::Mat(), mixed, cv::Mat::ones(size, CV_8UC1), cv::Mat::zeros(size, CV_8UC1)};
        for (const cv::Mat& grey : {smooth, binary, dark, bright})
            for (const cv::Mat& mask : masks)
                for (int alpha : {0, 1, 5, 300}) {
                    CensusImage fast, plain;
                    improvedCensus(grey, ec, alpha, mask, fast);
                    improvedCensusReference(grey, ec, alpha, mask, plain);
                    ASSERT_EQ(fast.data, plain.data) << size << " alpha " << alpha << " mask " << !mask.empty();
                }
    }
}

// Codes made a block of rows at a time (over stripes, or on the calling thread as the cost stage
// does), read through at(x, y) with the image's row, equal the whole image's, for both codes,
// blocks of awkward heights and a last block shorter than the others.
TEST(CensusEncoder, BlocksOfRowsEqualTheWholeImage) {
    const cv::Mat grey = test::randomImage(203, 77, CV_8UC1, 5);
    cv::Mat ec(grey.size(), CV_8UC1);
    cv::randu(ec, 0, 4);
    const cv::Mat mask = censusWindowMask(grey, 6.0);
    for (int code = 0; code < 3; ++code) {
        CensusEncoder encoder;
        CensusImage whole;
        if (code == 2) {
            encoder.prepareMei(grey);
            meiCensus(grey, whole);
        } else {
            const cv::Mat m = code == 0 ? mask : cv::Mat();
            encoder.prepareImproved(grey, ec, 3, m);
            improvedCensus(grey, ec, 3, m, whole);
        }
        for (int blockRows : {1, 10, 64, 77, 100}) {
            CensusImage block;
            for (int begin = 0; begin < grey.rows; begin += blockRows) {
                const int end = std::min(grey.rows, begin + blockRows);
                if (blockRows % 2) {
                    encoder.encodeRowsHere(begin, end, block);
                } else {
                    encoder.encodeRows(begin, end, block);
                }
                ASSERT_EQ(block.firstRow, begin);
                ASSERT_EQ(block.height, end - begin);
                for (int y = begin; y < end; ++y)
                    for (int x = 0; x < grey.cols; ++x)
                        for (int w = 0; w < whole.words; ++w)
                            ASSERT_EQ(block.at(x, y)[w], whole.at(x, y)[w])
                                << "code " << code << " block " << blockRows << " at " << x << "," << y;
            }
        }
    }
}

TEST(MeiCensus, CentreComparisons) {
    cv::Mat grey(7, 9, CV_8UC1, cv::Scalar(100));
    grey.at<std::uint8_t>(0, 0) = 10;  // first neighbour in the 9x7 window: darker, bit 61
    CensusImage census;
    meiCensus(grey, census);
    EXPECT_EQ(*census.at(4, 3), std::uint64_t{1} << 61);
}

}  // namespace
}  // namespace icewatch::stereo::detail
