#pragma once
// What the kernel says of huge pages, for the tests of memory_advice.h's allocator and of the
// program's operator new (tests/cli/large_allocations_test.cpp).
#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>

namespace streamrt::test {

inline std::uintptr_t address(const void* p) { return reinterpret_cast<std::uintptr_t>(p); }

/// Transparent huge pages on ([always] or [madvise]): advised mappings may take them.
inline bool huge_pages_possible() {
    std::ifstream in("/sys/kernel/mm/transparent_hugepage/enabled");
    std::stringstream s;
    s << in.rdbuf();
    return s.str().find("[madvise]") != std::string::npos || s.str().find("[always]") != std::string::npos;
}

/// The kernel's "THPeligible" for the mapping holding p (/proc/self/smaps): 1 when a fault
/// there may take a huge page. -1 when the mapping is not found.
inline int thp_eligible(const void* p) {
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

}  // namespace streamrt::test
