#pragma once
#include "materials/material_property.h"

namespace streamrt::property {

/// emission=R,G,B: the radiance the surface emits itself, added to its shaded colour at every
/// hit from degree 1 on (render/shading.h, shade_hit), whatever the lights, the checker or the
/// texture. It is not a light source: it lights no other surface and casts no shadow rays.
struct Emission {
    static constexpr PropertyInfo info{"emission", ValueKind::Colour};
    glm::dvec3 emission{0.0, 0.0, 0.0};
    static constexpr auto field = &Emission::emission;
};

}  // namespace streamrt::property
