// Large arrays in huge pages (core/memory_advice.h HugePageAllocator): alignment, the
// threshold, growth keeping the contents, and the kernel's view of the advice.
#include <doctest/doctest.h>

#include <cstdint>

#include "core/default_init.h"
#include "core/huge_pages_support.h"
#include "core/memory_advice.h"
#include "image/framebuffer.h"

using namespace streamrt;
using test::address;
using test::thp_eligible;

namespace {

constexpr std::uintptr_t kTwoMiB = std::uintptr_t(2) << 20;

}  // namespace

TEST_CASE("HugePageAllocator: 2 MiB blocks from 1 MiB, 64-byte alignment below") {
    HugePageAllocator<float> a;
    const std::size_t big = (std::size_t(1) << 20) / sizeof(float);  // exactly 1 MiB
    float* p = a.allocate(big);
    CHECK(address(p) % kTwoMiB == 0);
    float* q = a.allocate(big - 1);  // one float under the threshold
    CHECK(address(q) % 64 == 0);
    p[big - 1] = 1.f;                  // the whole array is usable
    q[big - 2] = 2.f;
    a.deallocate(q, big - 1);
    a.deallocate(p, big);
    CHECK_THROWS_AS((void)a.allocate(~std::size_t(0) / 2), std::bad_alloc);
}

TEST_CASE("LargeFillLaterVec keeps its contents as it grows into huge pages") {
    LargeFillLaterVec<std::uint32_t> v;
    for (std::uint32_t i = 0; i < 1000; ++i) v.push_back(i * 7);
    v.resize(std::size_t(3) << 20);  // 12 MiB: reallocated in blocks
    CHECK(address(v.data()) % kTwoMiB == 0);
    CHECK(v[0] == 0);
    CHECK(v[999] == 6993);
    v[v.size() - 1] = 42;
    CHECK(v.back() == 42);
}

TEST_CASE("A 1280x720 framebuffer is advised for huge pages") {
    const Framebuffer fb = Framebuffer::uninitialized(1280, 720);  // 11 MB
    CHECK(address(fb.rgb.data()) % kTwoMiB == 0);
    // With transparent huge pages on [always] or [madvise], the advice makes the mapping
    // eligible; under [never] (or without the file) nothing is asked of the kernel here.
    if (test::huge_pages_possible())
        CHECK(thp_eligible(fb.rgb.data()) == 1);
    else
        MESSAGE("transparent huge pages off: eligibility not checked");
}
