#include "core/common/huge_pages.hpp"

#include <cstdint>
#include <numeric>
#include <vector>

#include <gtest/gtest.h>

namespace icewatch {
namespace {

using HugeVector = std::vector<std::uint16_t, HugePageAllocator<std::uint16_t>>;

TEST(HugePageAllocator, LargeBlocksStartOnAHugePageBoundary) {
    HugeVector volume(3 * kHugePageSize / sizeof(std::uint16_t) + 5);
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(volume.data()) % kHugePageSize, 0u);
    // Value-initialised like any vector, and every element writable up to the last.
    EXPECT_EQ(volume.front(), 0);
    EXPECT_EQ(volume.back(), 0);
    std::iota(volume.begin(), volume.end(), std::uint16_t{0});
    EXPECT_EQ(volume[70000], static_cast<std::uint16_t>(70000));
}

TEST(HugePageAllocator, SmallBlocksAndRegrowthKeepTheContents) {
    HugeVector v(100, 7);
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(v.data()) % kCacheLine, 0u);
    v.resize(kHugePageSize);  // crosses from an ordinary block to a huge-page one
    EXPECT_EQ(v[99], 7);
    EXPECT_EQ(v[100], 0);
    HugeVector other(10, 3);
    std::swap(v, other);
    EXPECT_EQ(v.size(), 10u);
    EXPECT_EQ(other[99], 7);
}

}  // namespace
}  // namespace icewatch
