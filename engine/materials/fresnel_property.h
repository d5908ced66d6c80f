#pragma once
#include "materials/material_property.h"

namespace streamrt::property {

/// fresnel=true: at a dielectric (trans > 0) the split between refl and trans follows
/// Schlick's approximation instead of the fixed weights (render/shading.h, shade_hit).
struct Fresnel {
    static constexpr PropertyInfo info{"fresnel", ValueKind::Flag};
    bool fresnel = false;
    static constexpr auto field = &Fresnel::fresnel;
};

}  // namespace streamrt::property
