#pragma once
// Numbers as messages show them.
#include <cstdio>
#include <string>

namespace streamrt {

/// %g: "30", "0.25", "1e+06".
inline std::string fmt_num(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
}

}  // namespace streamrt
