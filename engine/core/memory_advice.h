#pragma once
// Advice to the kernel about large arrays (Linux madvise), for the scene reader and set-up.
#include <sys/mman.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <new>

namespace streamrt {

/// madvise over the whole `block`-aligned blocks inside [begin, end) (none when there are
/// none; 0: the page size). Used to give parsed text back (MADV_DONTNEED: read again from the
/// page cache if touched), to ask for huge pages for large arrays about to be filled
/// (MADV_HUGEPAGE: some hundreds of faults instead of 100 000s; the scene's objects, the
/// hierarchy builder's references, the stream engine's records) and to fault an array's
/// slices in from every thread (MADV_POPULATE_WRITE: zeroing the fresh pages of a
/// million-object array is a large part of reading a big scene, left to one thread otherwise).
inline void advise_inside(const void* begin, const void* end, int advice, std::uintptr_t block = 0) {
    if (block == 0) block = std::uintptr_t(::sysconf(_SC_PAGESIZE));
    const std::uintptr_t b = (std::uintptr_t(begin) + block - 1) & ~(block - 1);
    const std::uintptr_t e = std::uintptr_t(end) & ~(block - 1);
    if (e > b) ::madvise(reinterpret_cast<void*>(b), e - b, advice);
}

/// Huge pages for the 2 MiB blocks inside an array not yet written (a hint: ignored where
/// transparent huge pages are off).
template <class T>
inline void want_huge_pages(const T* begin, std::size_t count) {
    advise_inside(begin, begin + count, MADV_HUGEPAGE, std::uintptr_t(2) << 20);
}

/// Arrays from this size (bytes) are given whole huge pages (HugePageAllocator, and the
/// program's operator new: cli/large_allocations.cpp).
inline constexpr std::size_t kHugePagesFrom = std::size_t(1) << 20;
inline constexpr std::size_t kHugePageBlock = std::size_t(2) << 20;

/// `bytes` rounded up to whole 2 MiB blocks, 2 MiB-aligned and advised as huge pages (a
/// hint: nothing changes where transparent huge pages are off); null when the system has no
/// memory for it. Freed with std::free.
inline void* allocate_huge_blocks(std::size_t bytes) noexcept {
    if (bytes > std::numeric_limits<std::size_t>::max() - kHugePageBlock) return nullptr;
    const std::size_t whole = (bytes + kHugePageBlock - 1) & ~(kHugePageBlock - 1);
    void* p = std::aligned_alloc(kHugePageBlock, whole);
    if (p) ::madvise(p, whole, MADV_HUGEPAGE);
    return p;
}

/// An allocator for arrays that may be large and are written soon after they are made (a
/// framebuffer, an encoder's buffers): from 1 MiB an array gets whole 2 MiB blocks, aligned
/// to 2 MiB and advised as huge pages; below, 64-byte-aligned memory from operator new. First
/// writes to fresh memory are what such an array costs on a virtual machine (1 - 2 us a
/// 4 KiB page here, docs/performance.md "Fresh memory"); a huge page is one fault and one
/// clear. At most one partial block is left unused per array, and its tail is not touched.
template <class T>
struct HugePageAllocator {
    using value_type = T;
    static constexpr std::size_t kHugeFrom = kHugePagesFrom;  ///< bytes from which blocks are used
    static constexpr std::align_val_t kSmallAlign{64};

    HugePageAllocator() = default;
    template <class U>
    HugePageAllocator(const HugePageAllocator<U>&) noexcept {}

    T* allocate(std::size_t n) {
        if (n > (std::numeric_limits<std::size_t>::max() - kHugePageBlock) / sizeof(T)) throw std::bad_alloc();
        const std::size_t bytes = n * sizeof(T);
        if (bytes < kHugeFrom) return static_cast<T*>(::operator new(bytes, kSmallAlign));
        void* p = allocate_huge_blocks(bytes);
        if (!p) throw std::bad_alloc();
        return static_cast<T*>(p);
    }
    void deallocate(T* p, std::size_t n) noexcept {
        if (n * sizeof(T) < kHugeFrom) ::operator delete(p, kSmallAlign);
        else std::free(p);
    }
    template <class U>
    bool operator==(const HugePageAllocator<U>&) const noexcept {
        return true;
    }
};

}  // namespace streamrt
