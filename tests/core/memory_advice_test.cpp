// Large arrays in huge pages (core/memory_advice.h HugePageAllocator): alignment, the
// threshold, growth keeping the contents, and the kernel's view of the advice.
#include <doctest/doctest.h>

#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>

#include "core/default_init.h"
#include "core/memory_advice.h"
#include "image/framebuffer.h"

using namespace streamrt;

namespace {

constexpr std::uintptr_t kTwoMiB = std::uintptr_t(2) << 20;

std::uintptr_t address(const void* p) { return reinterpret_cast<std::uintptr_t>(p); }

std::string read_text(const char* path) {
    std::ifstream in(path);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

// The kernel's "THPeligible" for the mapping holding p (/proc/self/smaps): 1 when a fault
// there may take a huge page. -1 when the mapping is not found.
int thp_eligible(const void* p) {
    std::ifstream smaps("/proc/self/smaps");
    std::string line;
    bool inside = false;
    while (std::getline(smaps, line)) {
        std::uintptr_t lo = 0, hi = 0;
        char dash = 0;
        std::istringstream head(line);
        if (head >> std::hex >> lo >> dash >> hi && dash == '-') {
            inside = address(p) >= lo && address(p) < hi;
            continue;
        }
        if (inside && line.rfind("THPeligible:", 0) == 0) return std::stoi(line.substr(12));
    }
    return -1;
}

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
    const std::string mode = read_text("/sys/kernel/mm/transparent_hugepage/enabled");
    // With transparent huge pages on [always] or [madvise], the advice makes the mapping
    // eligible; under [never] (or without the file) nothing is asked of the kernel here.
    if (mode.find("[madvise]") != std::string::npos || mode.find("[always]") != std::string::npos)
        CHECK(thp_eligible(fb.rgb.data()) == 1);
    else
        MESSAGE("transparent huge pages off: eligibility not checked");
}
