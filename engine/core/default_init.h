#pragma once
// An allocator for large arrays that are written in full right after they are made.
#include <memory>

namespace streamrt {

/// std::allocator whose value-less construct() default-initialises (for trivial types: leaves
/// the memory untouched), so that an array every element of which is written next is not
/// zero-filled first: a framebuffer (12 GiB at 32768x32768), or the stream engine's object
/// records, whose pages are then first touched by the parallel loop that fills them.
template <class T>
struct DefaultInitAllocator : std::allocator<T> {
    template <class U>
    struct rebind {
        using other = DefaultInitAllocator<U>;
    };
    DefaultInitAllocator() = default;
    template <class U>
    DefaultInitAllocator(const DefaultInitAllocator<U>&) noexcept {}
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

}  // namespace streamrt
