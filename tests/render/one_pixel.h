#pragma once
// One-pixel scenes rendered by both engines, the pixel compared with a colour known in
// closed form (tests/render/degrees_test.cpp, tests/shapes/disk_test.cpp).
#include <doctest/doctest.h>

#include "driver/render.h"

namespace streamrt::test {

inline void check_one_pixel(const Scene& scene, double r, double g, double b) {
    for (EngineKind e : {EngineKind::Recursive, EngineKind::Stream}) {
        CAPTURE(engine_name(e));
        Parallelism par(1);
        const RenderResult res = render_scene(scene, e, par);
        const float* p = res.image.pixel(0, 0);
        CHECK(p[0] == doctest::Approx(r).epsilon(1e-5));
        CHECK(p[1] == doctest::Approx(g).epsilon(1e-5));
        CHECK(p[2] == doctest::Approx(b).epsilon(1e-5));
    }
}

}  // namespace streamrt::test
