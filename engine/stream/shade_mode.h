#pragma once
// How the stream engine's shade stage groups the hits of a generation for its SIMD kernel.
#include <cstdint>

#include "core/enum_names.h"

namespace streamrt {

enum class ShadeMode : std::uint8_t {
    Auto,      ///< by object up to a measured object count, by material and kind above it
    Sorted,    ///< runs of one object: its record broadcast into every lane
    Gathered,  ///< runs of one material and shape kind: each lane's object record gathered
    Scalar,    ///< one ray at a time (kept to measure the difference)
};
inline constexpr EnumName<ShadeMode> kShadeModeNames[] = {
    {ShadeMode::Auto, "simd"}, {ShadeMode::Sorted, "sorted"}, {ShadeMode::Gathered, "gathered"}, {ShadeMode::Scalar, "scalar"}};

}  // namespace streamrt
