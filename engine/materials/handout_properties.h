#pragma once
// The handout's optical parameters ("un jeu de paramètres"): the local terms' weights by
// degree, the mirror and transmission weights and the index of refraction. Their shading is
// render/shading.h's (direct_light, ambient_light, shade_hit's children).
#include "materials/material_property.h"

namespace streamrt::property {

struct Ambi {
    static constexpr PropertyInfo info{"ambi", ValueKind::Number, Bound::AtLeastZero};
    double ambi = 1.0;  ///< weight of the ambient term (degree >= 2)
    static constexpr auto field = &Ambi::ambi;
};

struct Diff {
    static constexpr PropertyInfo info{"diff", ValueKind::Number, Bound::AtLeastZero};
    double diff = 1.0;  ///< weight of the Lambert term (degree >= 2)
    static constexpr auto field = &Diff::diff;
};

struct Spec {
    static constexpr PropertyInfo info{"spec", ValueKind::Number, Bound::AtLeastZero};
    double spec = 0.0;  ///< weight of the Phong highlight (degree >= 2)
    static constexpr auto field = &Spec::spec;
};

struct Shininess {
    static constexpr PropertyInfo info{"shininess", ValueKind::Number, Bound::AtLeastZero};
    double shininess = 32.0;  ///< Phong exponent
    static constexpr auto field = &Shininess::shininess;
};

struct Refl {
    static constexpr PropertyInfo info{"refl", ValueKind::Number, Bound::AtLeastZero};
    double refl = 0.0;  ///< mirror reflection weight (degree >= 3)
    static constexpr auto field = &Refl::refl;
};

struct Trans {
    static constexpr PropertyInfo info{"trans", ValueKind::Number, Bound::AtLeastZero};
    double trans = 0.0;  ///< transmission weight (degree >= 4)
    static constexpr auto field = &Trans::trans;
};

struct Ior {
    static constexpr PropertyInfo info{"ior", ValueKind::Number, Bound::Positive};
    double ior = 1.0;  ///< index of refraction of the inside (the outside's is 1)
    static constexpr auto field = &Ior::ior;
};

}  // namespace streamrt::property
