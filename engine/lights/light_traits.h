#pragma once
// What every light kind declares (lights/lights.h checks it at compile time): its LightKind,
// its scene-format name, whether it is an area light, the keys its statement takes and those
// it needs, the checks beyond each key's own range, and one sample of its light seen from a
// point, written once for double, float and xsimd batches.
#include <glm/glm.hpp>

#include <string>
#include <string_view>

#include "core/format_number.h"
#include "lights/light.h"

namespace streamrt {

/// A light statement the kind refuses: the key whose value is at fault and the message
/// (`with_value`: the reader appends ", got '<the value as written>'"). Empty key: accepted.
struct LightProblem {
    std::string_view key;
    std::string message;
    bool with_value = false;
};

}  // namespace streamrt
