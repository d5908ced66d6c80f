// The stream pipeline is built from what the scene uses: no occlusion stage without shadows,
// no spawn stages without mirrors or glass, centre sampling at one sample per pixel, and a
// kernel only for the shape kinds present. The profile counts what ran.
#include <doctest/doctest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "kernels/kernel_table.h"
#include "parallel/parallelism.h"
#include "driver/render.h"
#include "scene/parser.h"
#include "stream/profile.h"
#include "stream/stream_renderer.h"

using namespace streamrt;

namespace {

std::vector<std::string> stages_of(const std::string& text) {
    const Scene scene = parse_scene(text, "pipeline_features_test.cfg");
    return StreamRenderer(scene, best_isa()).built_stages();
}

bool has(const std::vector<std::string>& v, const std::string& s) { return std::find(v.begin(), v.end(), s) != v.end(); }
bool has_prefix(const std::vector<std::string>& v, const std::string& p) {
    return std::any_of(v.begin(), v.end(), [&](const std::string& s) { return s.rfind(p, 0) == 0; });
}
std::string intersect_of(const std::vector<std::string>& v) {
    for (const std::string& s : v)
        if (s.rfind("intersect[", 0) == 0) return s;
    return "";
}
std::string joined(const std::vector<std::string>& v) {
    std::string s;
    for (const auto& x : v) s += x + " ";
    return s;
}

const char* kCamera = "camera eye=0,1,6 look=0,0,0\n";
const char* kLight = "light point pos=3,5,4\n";
const char* kMatte = "sphere color=1,0,0\n";
const char* kMirror = "sphere refl=0.8 translate=2,0,0\n";
const char* kGlass = "sphere trans=0.9 ior=1.5 translate=-2,0,0\n";

std::string scene(int degree, int depth, int spp, bool light, const std::string& objects) {
    return "image width=32 height=24 spp=" + std::to_string(spp) + " depth=" + std::to_string(depth) +
           " degree=" + std::to_string(degree) + "\n" + kCamera + (light ? kLight : "") + objects;
}

}  // namespace

TEST_CASE("pipeline: occlusion only at degree 5 with a light") {
    const std::string objs = std::string(kMatte) + "plane translate=0,-1,0\n";
    for (int degree = 0; degree <= 5; ++degree) {
        CAPTURE(degree);
        const auto lit = stages_of(scene(degree, 3, 1, true, objs));
        const auto dark = stages_of(scene(degree, 3, 1, false, objs));
        CAPTURE(joined(lit));
        CHECK(has_prefix(lit, "occlusion") == (degree == 5));
        CHECK_FALSE(has_prefix(dark, "occlusion"));
        CHECK(has_prefix(lit, degree >= 1 ? "shade(lit," : "shade(flat,"));
        CHECK(has(lit, "accumulate"));
    }
    CHECK(has(stages_of(scene(5, 3, 1, true, objs)), "occlusion(any-hit)"));
}

TEST_CASE("pipeline: spawn stages only with reflective or transmissive materials, degree and depth") {
    const std::string all = std::string(kMatte) + kMirror + kGlass;
    // Matte only: no spawn at any degree.
    for (int degree = 0; degree <= 5; ++degree) {
        CAPTURE(degree);
        const auto st = stages_of(scene(degree, 4, 1, true, kMatte));
        CHECK_FALSE(has_prefix(st, "spawn"));
    }
    // Mirror and glass: reflect from degree 3, refract from degree 4, never at depth 0.
    for (int degree = 0; degree <= 5; ++degree)
        for (int depth : {0, 1, 4}) {
            CAPTURE(degree);
            CAPTURE(depth);
            const auto st = stages_of(scene(degree, depth, 1, true, all));
            CAPTURE(joined(st));
            CHECK(has(st, "spawn(reflect)") == (degree >= 3 && depth >= 1));
            CHECK(has(st, "spawn(refract)") == (degree >= 4 && depth >= 1));
        }
    // Mirror only / glass only.
    CHECK(has(stages_of(scene(5, 2, 1, true, kMirror)), "spawn(reflect)"));
    CHECK_FALSE(has(stages_of(scene(5, 2, 1, true, kMirror)), "spawn(refract)"));
    CHECK_FALSE(has(stages_of(scene(5, 2, 1, true, kGlass)), "spawn(reflect)"));
    CHECK(has(stages_of(scene(5, 2, 1, true, kGlass)), "spawn(refract)"));
}

TEST_CASE("pipeline: centre sampling at spp 1, jittered above") {
    CHECK(has(stages_of(scene(2, 1, 1, true, kMatte)), "generate(centre)"));
    CHECK_FALSE(has(stages_of(scene(2, 1, 1, true, kMatte)), "generate(jittered)"));
    for (int spp : {2, 4, 9}) {
        CAPTURE(spp);
        CHECK(has(stages_of(scene(2, 1, spp, true, kMatte)), "generate(jittered)"));
        CHECK_FALSE(has(stages_of(scene(2, 1, spp, true, kMatte)), "generate(centre)"));
    }
}

TEST_CASE("pipeline: intersect kernels only for the shape kinds present, in kind order") {
    CHECK(intersect_of(stages_of(scene(5, 1, 1, true, kMatte))) == "intersect[sphere]");
    CHECK(intersect_of(stages_of(scene(5, 1, 1, true, "cube\ncube translate=3,0,0\n"))) == "intersect[cube]");
    CHECK(intersect_of(stages_of(scene(5, 1, 1, true, "plane\ncone\nsphere\n"))) == "intersect[sphere,cone,plane]");
    CHECK(intersect_of(stages_of(scene(5, 1, 1, true, "torus minor=0.3\ncylinder\n"))) == "intersect[cylinder,torus]");
    CHECK(intersect_of(stages_of(scene(5, 1, 1, true,
                                       "plane\ncone\nsphere\ncube\ncylinder\ntorus\n"))) ==
          "intersect[sphere,cube,cylinder,cone,torus,plane]");
    CHECK(intersect_of(stages_of(scene(5, 1, 1, true, ""))) == "intersect[]");
}

TEST_CASE("pipeline: the profile counts width*height*spp primary rays and lane use in [0, 1]") {
    struct Case {
        int w, h, spp, degree;
        const char* objs;
        bool light;
    };
    const Case cases[] = {
        {32, 24, 1, 5, "sphere refl=0.5\nplane translate=0,-1,0\n", true},
        {37, 19, 3, 5, "sphere trans=0.9 ior=1.5\ncube translate=2,0,0\ntorus translate=-2,0,0\n", true},
        {17, 33, 4, 0, "cone\n", false},
        {16, 16, 2, 3, "cylinder refl=0.7\n", true},
    };
    for (const Case& c : cases) {
        CAPTURE(c.w); CAPTURE(c.h); CAPTURE(c.spp); CAPTURE(c.degree); CAPTURE(c.objs);
        std::string text = "image width=" + std::to_string(c.w) + " height=" + std::to_string(c.h) +
                           " spp=" + std::to_string(c.spp) + " depth=3 degree=" + std::to_string(c.degree) + "\n" +
                           kCamera + (c.light ? kLight : "") + c.objs;
        const Scene sc = parse_scene(text, "profile_test.cfg");
        for (int jobs : {1, 2}) {
            CAPTURE(jobs);
            StreamProfile prof;
            Parallelism par(jobs);
            EngineOptions opt;
            opt.profile = &prof;
            const RenderResult r = render_scene(sc, EngineKind::Stream, par, nullptr, opt);
            const std::uint64_t primary = std::uint64_t(c.w) * std::uint64_t(c.h) * std::uint64_t(c.spp);
            CHECK(prof.counts.primary == primary);
            CHECK(r.counts.primary == primary);
            CHECK(prof.stages[int(Stage::Generate)].rays_out == primary);
            CHECK(prof.stages[int(Stage::Generate)].rays_in == std::uint64_t(c.w) * std::uint64_t(c.h));
            CHECK(prof.stages[int(Stage::Accumulate)].rays_in == std::uint64_t(c.w) * std::uint64_t(c.h));
            CHECK(prof.stages[int(Stage::Intersect)].rays_in >= primary);
            CHECK(prof.counts.shadow == prof.stages[int(Stage::Occlusion)].rays_in);
            CHECK(prof.threads == jobs);
            CHECK(prof.isa == std::string(isa_name(best_isa())));
            CHECK(prof.lanes == kernel_table(best_isa()).float_lanes);
            CHECK(prof.built == StreamRenderer(sc, best_isa()).built_stages());
            for (Stage s : {Stage::Intersect, Stage::Occlusion}) {
                const StageFigures& f = prof.stages[int(s)];
                const std::string stage_str = stage_name(s);
                CAPTURE(stage_str);
                CHECK(f.lanes_used <= f.lanes_total);
                if (f.lanes_total > 0) {
                    const double use = double(f.lanes_used) / double(f.lanes_total);
                    CHECK(use > 0.0);
                    CHECK(use <= 1.0);
                }
            }
            CHECK(prof.stages[int(Stage::Intersect)].lanes_total > 0);
            const bool shadows = c.degree == 5 && c.light;
            CHECK((prof.stages[int(Stage::Occlusion)].rays_in > 0) == shadows);
        }
    }
}
