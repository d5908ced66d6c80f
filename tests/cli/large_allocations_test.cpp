// The program's operator new (engine/cli/large_allocations.cpp, linked into this test program
// too): from 1 MiB, whole 2 MiB blocks advised as huge pages; below, malloc; the standard's
// alignment, nothrow and new-handler behaviour kept.
#include <doctest/doctest.h>

#include <malloc.h>

#include <cstdint>
#include <new>
#include <vector>

#include "core/huge_pages_support.h"
#include "core/memory_advice.h"

using streamrt::test::address;
using streamrt::test::huge_pages_possible;
using streamrt::test::thp_eligible;

namespace {

constexpr std::uintptr_t kTwoMiB = std::uintptr_t(2) << 20;

int handler_calls = 0;
void count_and_give_up() {
    ++handler_calls;
    std::set_new_handler(nullptr);  // the next failure throws
}

}  // namespace

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
TEST_CASE("operator new: large allocations in huge pages (not in sanitizer builds)") {
    MESSAGE("sanitizer build: the sanitizer's own operator new is in use");
}
#else
TEST_CASE("operator new: 1 MiB and more in whole 2 MiB blocks, smaller from malloc") {
    std::vector<float> big(std::size_t(1) << 18);  // exactly 1 MiB
    CHECK(address(big.data()) % kTwoMiB == 0);
    CHECK(malloc_usable_size(big.data()) >= kTwoMiB);  // a whole block
    big.back() = 1.f;
    std::vector<char> small((std::size_t(1) << 20) - 1);  // one byte under
    CHECK(malloc_usable_size(small.data()) < kTwoMiB);
    CHECK(malloc_usable_size(small.data()) >= small.size());
    if (huge_pages_possible()) CHECK(thp_eligible(big.data()) == 1);
    else MESSAGE("transparent huge pages off: eligibility not checked");
}

TEST_CASE("operator new: aligned, nothrow and the new-handler as the standard asks") {
    void* a = ::operator new(100, std::align_val_t(256));
    CHECK(address(a) % 256 == 0);
    ::operator delete(a, std::align_val_t(256));
    void* b = ::operator new(std::size_t(3) << 20, std::align_val_t(4096));  // large: a block
    CHECK(address(b) % kTwoMiB == 0);
    ::operator delete(b, std::align_val_t(4096));
    const std::size_t impossible = std::size_t(1) << 62;  // 4 EiB: no system has it
    CHECK(::operator new(impossible, std::nothrow) == nullptr);
    CHECK(::operator new[](impossible, std::align_val_t(64), std::nothrow) == nullptr);
    handler_calls = 0;
    std::set_new_handler(count_and_give_up);
    CHECK_THROWS_AS((void)::operator new(impossible), std::bad_alloc);
    CHECK(handler_calls == 1);
    CHECK(!std::get_new_handler());
}
#endif
