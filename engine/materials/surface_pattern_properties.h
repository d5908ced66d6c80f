#pragma once
// What replaces the object's colour on the surface: the checker pattern (render/shading.h,
// surface_color), the texture image and a mesh's vertex colours (render/texture.h).
#include "materials/material_property.h"

namespace streamrt::property {

/// checker=R,G,B: the second colour of the checker pattern, which the key turns on.
struct Checker {
    static constexpr PropertyInfo info{"checker", ValueKind::Colour};
    bool checker = false;                     ///< the pattern is on (checker= was given)
    glm::dvec3 checker_color{0.0, 0.0, 0.0};  ///< the colour of the odd cells
    static constexpr auto field = &Checker::checker_color;
    static constexpr auto given = &Checker::checker;
};

struct Cell {
    static constexpr PropertyInfo info{"cell", ValueKind::Number, Bound::Positive};
    double cell = 1.0;  ///< checker cell side, world units
    static constexpr auto field = &Cell::cell;
};

/// texture=FILE (docs/scene-format.md, "Textures and UV mapping").
struct Texture {
    static constexpr PropertyInfo info{"texture", ValueKind::Image};
    std::int32_t texture = -1;  ///< index into Scene::textures; -1: the object's colour
    static constexpr auto field = &Texture::texture;
};

/// vertex_colors=true: a mesh's colours at its vertices (a PLY file's red green blue, an OBJ
/// file's v x y z r g b), interpolated across each triangle, replace the object's colour
/// (render/texture.h).
struct VertexColors {
    static constexpr PropertyInfo info{"vertex_colors", ValueKind::Flag, Bound::Any, true};
    bool vertex_colors = false;
    static constexpr auto field = &VertexColors::vertex_colors;
};

struct UvScale {
    static constexpr PropertyInfo info{"uvscale", ValueKind::Number, Bound::Positive};
    double uv_scale = 1.0;  ///< multiplies (u, v) before the lookup (tiling)
    static constexpr auto field = &UvScale::uv_scale;
};

}  // namespace streamrt::property
