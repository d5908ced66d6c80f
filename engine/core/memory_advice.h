#pragma once
// Advice to the kernel about large arrays (Linux madvise), for the scene reader and set-up.
#include <sys/mman.h>
#include <unistd.h>

#include <cstdint>

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

}  // namespace streamrt
