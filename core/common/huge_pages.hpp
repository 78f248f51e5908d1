#pragma once
// An allocator for the few large buffers that are walked down their columns (the cost volumes):
// each row of such a buffer lies on another 4 KiB page, so a column pass needs a new address
// translation for nearly every access and runs out of TLB entries long before it runs out of cache.
// Blocks of 2 MiB and more are aligned to 2 MiB and offered to the kernel as transparent huge pages
// (madvise), one translation per 2 MiB instead of 512. Where the kernel has them off, or on systems
// without madvise, this is an ordinary aligned allocation; the contents never depend on it.
// Every block starts a 64-byte cache line, so records of 64 bytes (a census code) never straddle two.
#include <cstddef>
#include <cstdlib>
#include <new>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace icewatch {

inline constexpr std::size_t kHugePageSize = std::size_t{2} << 20;
inline constexpr std::size_t kCacheLine = 64;

template <class T>
struct HugePageAllocator {
    using value_type = T;

    HugePageAllocator() = default;
    template <class U>
    explicit HugePageAllocator(const HugePageAllocator<U>&) noexcept {}

    T* allocate(std::size_t n) {
        if (n > static_cast<std::size_t>(-1) / sizeof(T) - kHugePageSize) throw std::bad_array_new_length();
        const std::size_t bytes = n * sizeof(T);
        if (bytes < kHugePageSize) return static_cast<T*>(::operator new(bytes, std::align_val_t{kCacheLine}));
        // aligned_alloc wants a multiple of the alignment.
        const std::size_t rounded = (bytes + kHugePageSize - 1) / kHugePageSize * kHugePageSize;
        void* p = std::aligned_alloc(kHugePageSize, rounded);
        if (!p) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
        ::madvise(p, rounded, MADV_HUGEPAGE);  // advice only: failure leaves ordinary pages
#endif
        return static_cast<T*>(p);
    }
    void deallocate(T* p, std::size_t n) noexcept {
        if (n * sizeof(T) < kHugePageSize) {
            ::operator delete(p, std::align_val_t{kCacheLine});
        } else {
            std::free(p);
        }
    }

    template <class U>
    bool operator==(const HugePageAllocator<U>&) const noexcept {
        return true;
    }
};

// A vector whose data starts a cache line (and, from 2 MiB on, a huge page).
template <class T>
using AlignedVector = std::vector<T, HugePageAllocator<T>>;

}  // namespace icewatch
