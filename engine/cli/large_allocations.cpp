// The streamrt program's operator new: an allocation of 1 MiB or more gets whole 2 MiB
// blocks advised as huge pages (core/memory_advice.h allocate_huge_blocks), smaller ones come
// from malloc as before. On this project's virtual machines the first write to a fresh 4 KiB
// page costs 1 - 7 us, so the arrays that reading a large mesh fills once (its triangles in
// leaf order, their blocks, the hierarchy's references and nodes, the vertex normals: some
// 14,000 fresh pages for a 235k-triangle mesh) cost more in page faults than in work; in huge
// pages they are a few dozen faults (docs/performance.md, "Start-up").
// Linked into the program, the test program and mesh_build_bench (whose first build is what
// a render's reading sees), not into the engine library: the Python module leaves the host's
// allocator alone. Sanitizer builds keep their own operator new, which checks every allocation.
#include <cstddef>
#include <cstdlib>
#include <new>

#include "core/memory_advice.h"

#if !defined(__SANITIZE_ADDRESS__) && !defined(__SANITIZE_THREAD__)

namespace {

void* try_allocate(std::size_t bytes, std::size_t align) noexcept {
    if (bytes >= streamrt::kHugePagesFrom && align <= streamrt::kHugePageBlock)
        return streamrt::allocate_huge_blocks(bytes);
    if (bytes == 0) bytes = 1;  // a distinct address for every allocation
    if (align <= alignof(std::max_align_t)) return std::malloc(bytes);
    // aligned_alloc wants a size that is a multiple of the alignment.
    const std::size_t rounded = (bytes + align - 1) / align * align;
    return rounded < bytes ? nullptr : std::aligned_alloc(align, rounded);
}

/// The standard's loop: call the new-handler until it gives memory or there is none.
void* allocate(std::size_t bytes, std::size_t align) {
    for (;;) {
        if (void* p = try_allocate(bytes, align)) return p;
        const std::new_handler handler = std::get_new_handler();
        if (!handler) throw std::bad_alloc();
        handler();
    }
}

void* allocate_nothrow(std::size_t bytes, std::size_t align) noexcept {
    try {
        return allocate(bytes, align);
    } catch (...) {
        return nullptr;
    }
}

}  // namespace

// Every block comes from the malloc family (malloc, aligned_alloc), so every delete is free.
void* operator new(std::size_t n) { return allocate(n, 0); }
void* operator new[](std::size_t n) { return allocate(n, 0); }
void* operator new(std::size_t n, std::align_val_t a) { return allocate(n, std::size_t(a)); }
void* operator new[](std::size_t n, std::align_val_t a) { return allocate(n, std::size_t(a)); }
void* operator new(std::size_t n, const std::nothrow_t&) noexcept { return allocate_nothrow(n, 0); }
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept { return allocate_nothrow(n, 0); }
void* operator new(std::size_t n, std::align_val_t a, const std::nothrow_t&) noexcept {
    return allocate_nothrow(n, std::size_t(a));
}
void* operator new[](std::size_t n, std::align_val_t a, const std::nothrow_t&) noexcept {
    return allocate_nothrow(n, std::size_t(a));
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept { std::free(p); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept { std::free(p); }

#endif
