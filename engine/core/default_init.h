#pragma once
// An allocator for large arrays that are written in full right after they are made.
#include <memory>
#include <vector>

#include "core/memory_advice.h"
#include "simd/lanes.h"

namespace streamrt {

/// An allocator (std::allocator, or `Base`) whose value-less construct() default-initialises
/// (for trivial types: leaves the memory untouched), so that an array every element of which
/// is written next is not zero-filled first: a framebuffer (12 GiB at 32768x32768), the
/// stream engine's object records, a mesh's triangle blocks, whose pages are then first
/// touched by the parallel loop that fills them.
template <class T, class Base = std::allocator<T>>
struct DefaultInitAllocator : Base {
    template <class U>
    struct rebind {
        using other = DefaultInitAllocator<U, typename std::allocator_traits<Base>::template rebind_alloc<U>>;
    };
    DefaultInitAllocator() = default;
    template <class U, class B>
    DefaultInitAllocator(const DefaultInitAllocator<U, B>&) noexcept {}
    template <class U>
    void construct(U* p) noexcept {
        ::new (static_cast<void*>(p)) U;
    }
    template <class U, class... Args>
    void construct(U* p, Args&&... args) {
        ::new (static_cast<void*>(p)) U(static_cast<Args&&>(args)...);
    }
};

/// A vector whose resize() leaves trivial elements uninitialised.
template <class T>
using FillLaterVec = std::vector<T, DefaultInitAllocator<T>>;
/// The same, aligned as simd::AlignedVec.
template <class T>
using AlignedFillLaterVec = std::vector<T, DefaultInitAllocator<T, xsimd::aligned_allocator<T, simd::kAlign>>>;

/// The same, in huge pages once it reaches 1 MiB (HugePageAllocator): images and other
/// large buffers filled right after they are made.
template <class T>
using LargeFillLaterVec = std::vector<T, DefaultInitAllocator<T, HugePageAllocator<T>>>;

}  // namespace streamrt
