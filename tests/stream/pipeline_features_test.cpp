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

TEST_CASE("pipeline: the diffuse spawn stage only at degree 6, with a diffuse material and depth") {
    // Matte (diff 1 by default): bounces at degree 6 from depth 1; never below degree 6.
    for (int degree = 0; degree <= 6; ++degree)
        for (int depth : {0, 2}) {
            CAPTURE(degree);
            CAPTURE(depth);
            const auto st = stages_of(scene(degree, depth, 1, true, kMatte));
            CAPTURE(joined(st));
            CHECK(has(st, "spawn(diffuse)") == (degree == 6 && depth >= 1));
        }
    // Mirrors and glass without a diffuse part: degree 5's stages, no diffuse spawn.
    const auto specular = stages_of(scene(6, 3, 1, true,
                                          "sphere diff=0 refl=0.8 translate=2,0,0\nsphere diff=0 trans=0.9 ior=1.5\n"));
    CAPTURE(joined(specular));
    CHECK_FALSE(has(specular, "spawn(diffuse)"));
    CHECK(has(specular, "spawn(reflect)"));
    CHECK(has(specular, "spawn(refract)"));
    CHECK(has(specular, "occlusion(any-hit)"));
    // Lit by the sky alone: bounces, no occlusion stage.
    const auto sky = stages_of(scene(6, 3, 1, false, kMatte));
    CHECK(has(sky, "spawn(diffuse)"));
    CHECK_FALSE(has_prefix(sky, "occlusion"));
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

TEST_CASE("pipeline: each scene builds exactly the stages written here, and the profile reports them") {
    // Written by hand from the scene text (docs/architecture.md's stage list): which stages and
    // kernels a scene must build and which it must not. Few objects: the shade stage runs
    // sorted runs of one object (ShadeMode::Auto below its object-count threshold).
    struct Case {
        int w, h, spp, degree;
        const char* objs;
        bool light;
        std::vector<std::string> built;
    };
    const Case cases[] = {
        // a mirror (refl) and a matte plane, lit at degree 5: reflect and shadows, no refract
        {32, 24, 1, 5, "sphere refl=0.5\nplane translate=0,-1,0\n", true,
         {"generate(centre)", "intersect[sphere,plane]", "shade(lit,simd,sorted)", "spawn(reflect)",
          "occlusion(any-hit)", "accumulate"}},
        // glass (trans, no refl) at 3 spp: jittered, refract only, shadows
        {37, 19, 3, 5, "sphere trans=0.9 ior=1.5\ncube translate=2,0,0\ntorus translate=-2,0,0\n", true,
         {"generate(jittered)", "intersect[sphere,cube,torus]", "shade(lit,simd,sorted)", "spawn(refract)",
          "occlusion(any-hit)", "accumulate"}},
        // degree 0: flat colour, no light, no spawn, no shadows
        {17, 33, 4, 0, "cone\n", false,
         {"generate(jittered)", "intersect[cone]", "shade(flat,simd,sorted)", "accumulate"}},
        // degree 3 with a mirror: lit and reflect, but no shadow rays below degree 5
        {16, 16, 2, 3, "cylinder refl=0.7\n", true,
         {"generate(jittered)", "intersect[cylinder]", "shade(lit,simd,sorted)", "spawn(reflect)", "accumulate"}},
    };
    for (const Case& c : cases) {
        CAPTURE(c.w); CAPTURE(c.h); CAPTURE(c.spp); CAPTURE(c.degree); CAPTURE(c.objs);
        std::string text = "image width=" + std::to_string(c.w) + " height=" + std::to_string(c.h) +
                           " spp=" + std::to_string(c.spp) + " depth=3 degree=" + std::to_string(c.degree) + "\n" +
                           kCamera + (c.light ? kLight : "") + c.objs;
        const Scene sc = parse_scene(text, "profile_test.cfg");
        CHECK(joined(StreamRenderer(sc, best_isa()).built_stages()) == joined(c.built));
        for (int jobs : {1, 2}) {
            CAPTURE(jobs);
            StreamProfile prof;
            Parallelism par(jobs);
            EngineOptions opt;
            opt.profile = &prof;
            const RenderResult r = render_scene(sc, EngineKind::Stream, par, nullptr, opt);
            const std::uint64_t primary = std::uint64_t(c.w) * std::uint64_t(c.h) * std::uint64_t(c.spp);
            CHECK(joined(prof.built) == joined(c.built));
            CHECK(prof.counts.primary == primary);
            CHECK(r.counts.primary == primary);
            CHECK(prof.stages[int(Stage::Generate)].rays_out == primary);
            CHECK(prof.stages[int(Stage::Generate)].rays_in == std::uint64_t(c.w) * std::uint64_t(c.h));
            CHECK(prof.stages[int(Stage::Accumulate)].rays_in == std::uint64_t(c.w) * std::uint64_t(c.h));
            CHECK(prof.stages[int(Stage::Intersect)].rays_in >= primary);
            CHECK(prof.counts.shadow == prof.stages[int(Stage::Occlusion)].rays_in);
            CHECK(prof.threads == jobs);
            CHECK(prof.isa == std::string(isa_name(best_isa())));
            const bool shadows = c.degree == 5 && c.light;
            CHECK((prof.stages[int(Stage::Occlusion)].rays_in > 0) == shadows);
        }
    }
}

TEST_CASE("pipeline: lane figures of the intersect stage, counted by hand") {
    // 17x33 at 4 spp, degree 0 (no spawned or shadow ray), one cone: the intersect stage sees
    // the primary rays only, one kernel call per 16x16 tile (a tile is one chunk: at most 4096
    // rays). Tiles: 16x16, 1x16, 16x16, 1x16, 16x1, 1x1 pixels = 256, 16, 256, 16, 16, 1, times
    // 4 spp: 1024, 64, 1024, 64, 64, 4 rays (2244 = 17*33*4). A call on n rays runs n rounded
    // up to the lane width L: L = 16 (AVX-512): 1024+64+1024+64+64+16 = 2256; L = 8 (AVX2):
    // 1024+64+1024+64+64+8 = 2248; L = 4 (SSE): 2244. The torus kernel runs in double, L/2
    // lanes; with a torus in place of the cone: L/2 = 8: 2248, 4: 2244, 2: 2244.
    const std::string head = "image width=17 height=33 spp=4 depth=3 degree=0\n" + std::string(kCamera);
    for (Isa isa : {Isa::Sse2, Isa::Sse42, Isa::Avx2, Isa::Avx512}) {
        if (!isa_supported(isa)) continue;
        const std::string isa_str = isa_name(isa);
        CAPTURE(isa_str);
        const int L = isa == Isa::Avx512 ? 16 : isa == Isa::Avx2 ? 8 : 4;
        CHECK(kernel_table(isa).float_lanes == L);
        for (const bool torus : {false, true}) {
            CAPTURE(torus);
            const Scene sc = parse_scene(head + (torus ? "torus minor=0.3\n" : "cone\n"), "lanes_test.cfg");
            StreamProfile prof;
            Parallelism par(2);
            EngineOptions opt;
            opt.profile = &prof;
            opt.isa = isa;
            render_scene(sc, EngineKind::Stream, par, nullptr, opt);
            const StageFigures& f = prof.stages[int(Stage::Intersect)];
            const int lanes = torus ? L / 2 : L;
            const std::uint64_t expected_total = lanes == 16 ? 2256 : lanes == 8 ? 2248 : 2244;
            CHECK(f.rays_in == 2244);
            CHECK(f.lanes_used == 2244);
            CHECK(f.lanes_total == expected_total);
            CHECK(prof.stages[int(Stage::Occlusion)].lanes_total == 0);
        }
    }
}

TEST_CASE("pipeline: area lights' samples go through the occlusion stage, and only when present") {
    const std::string objs = std::string(kMatte) + "plane translate=0,-1,0\n";
    const std::string base = "image width=32 height=24 spp=2 depth=0 degree=5\n" + std::string(kCamera) + objs;
    // The handout's lights (and falloff / soft edges, which need no samples): no keys, the
    // plain occlusion stage.
    CHECK(has(stages_of(base + kLight), "occlusion(any-hit)"));
    CHECK(has(stages_of(base + "light point pos=3,5,4 falloff=inverse_square\n"), "occlusion(any-hit)"));
    // A sphere light of 9 samples and a rect light of 4: 13 shadow rays per hit for them.
    const auto area = stages_of(base + "light sphere pos=3,5,4 radius=1 samples=9\n"
                                       "light rect pos=-3,5,0 u=1,0,0 v=0,0,1 samples=4\n" + kLight);
    CAPTURE(joined(area));
    CHECK(has(area, "occlusion(any-hit,area x 13)"));
    // Without shadows the samples still light the hit, with no occlusion stage.
    const std::string dim = "image width=32 height=24 spp=2 depth=0 degree=2\n" + std::string(kCamera) + objs;
    const auto unshadowed = stages_of(dim + "light sphere pos=3,5,4 radius=1 samples=9\n");
    CHECK_FALSE(has_prefix(unshadowed, "occlusion"));
    CHECK(has(unshadowed, "area lights x 9 (no shadows)"));
}

// The stages a scene needs, checked by what they do rather than by their labels: a camera
// looking straight down at the canonical plane (y = 0, infinite) sees it in every pixel, and a
// light straight above lights every point of it, so every ray count follows by hand from the
// scene text. A stage the scene does not need must not run at all: no ray in, no CPU time.
// Proven against: the occlusion stage built from degree 3 (stream_scene.cpp: shadow rays
// counted at degree 3, and the stage's CPU time); the occlusion stage built without a light
// (no ray, but the stage ran: its CPU time). Not seen here, since no count changes: the
// spawn stage built for a scene with no mirror (refl=0 spawns nothing either way); the stage
// lists above catch that one.
TEST_CASE("pipeline: ray counts of each stage, worked out by hand on a plane seen from above") {
    constexpr int W = 20, H = 15, S = 2;
    constexpr std::uint64_t P = std::uint64_t(W) * H * S;  // primary rays; every one hits the plane
    struct Case {
        int degree;
        const char* plane;
        bool light;
        std::uint64_t intersect, shadow, reflected, refracted;
    };
    const Case cases[] = {
        // matte, lit, degree 5: one shadow ray per hit, nothing spawned
        {5, "plane", true, P, P, 0, 0},
        // a mirror: each hit spawns a reflected ray (upwards: it meets nothing); shadow rays from
        // the primary hits only
        {5, "plane refl=0.5", true, 2 * P, P, P, 0},
        // a glass plane: each hit spawns a refracted ray (downwards, through: nothing beyond)
        {5, "plane trans=0.5 ior=1.5", true, 2 * P, P, 0, P},
        // degree 3: reflections but no shadow rays
        {3, "plane refl=0.5", true, 2 * P, 0, P, 0},
        // degree 2: neither
        {2, "plane refl=0.5 trans=0.5", true, P, 0, 0, 0},
        // no light: no shadow rays even at degree 5
        {5, "plane refl=0.5", false, 2 * P, 0, P, 0},
        // glass without a Lambert term or highlight: the light could add nothing, so no
        // shadow ray leaves it (the same pixels: render/shading.h, DirectLight::contributes)
        {5, "plane trans=0.5 ior=1.5 diff=0 spec=0", true, 2 * P, 0, 0, P},
    };
    for (const Case& c : cases) {
        CAPTURE(c.degree); CAPTURE(c.plane); CAPTURE(c.light);
        const std::string text = "image width=" + std::to_string(W) + " height=" + std::to_string(H) +
                                 " spp=" + std::to_string(S) + " depth=4 degree=" + std::to_string(c.degree) +
                                 "\ncamera eye=0,5,0 look=0,0,0 up=0,0,-1 fov=40\n" +
                                 (c.light ? "light point pos=0,10,0\n" : "") + c.plane + "\n";
        const Scene sc = parse_scene(text, "plane_counts.cfg");
        StreamProfile prof;
        Parallelism par(1);
        EngineOptions opt;
        opt.profile = &prof;
        const RenderResult r = render_scene(sc, EngineKind::Stream, par, nullptr, opt);
        CHECK(r.counts.primary == P);
        CHECK(r.counts.shadow == c.shadow);
        CHECK(r.counts.reflected == c.reflected);
        CHECK(r.counts.refracted == c.refracted);
        CHECK(prof.stages[int(Stage::Intersect)].rays_in == c.intersect);
        // Every shadow ray reaches the light: nothing but the plane, which it leaves.
        CHECK(prof.stages[int(Stage::Occlusion)].rays_in == c.shadow);
        CHECK(prof.stages[int(Stage::Occlusion)].rays_out == c.shadow);
        if (c.shadow == 0 && !std::string(c.plane).empty() && std::string(c.plane).find("diff=0") == std::string::npos)
            CHECK(prof.stages[int(Stage::Occlusion)].nanoseconds == 0);
    }
}

// Proven against: shadow rays sent wherever the light reaches (send = lit, the old rule):
// every hit of the highlight-only mirror casts one (P instead of a part of P), and the
// diff=0 spec=0 glass above casts P.
TEST_CASE("pipeline: a surface without a Lambert term casts shadow rays only where its highlight shows") {
    // The plane seen from above, a mirror with a narrow highlight (shininess 200) and no
    // Lambert term: the light straight above shows in the middle of the picture only.
    constexpr int W = 20, H = 15;
    constexpr std::uint64_t P = std::uint64_t(W) * H;
    const std::string text = "image width=20 height=15 depth=1 degree=5\ncamera eye=0,5,0 look=0,0,0 up=0,0,-1 fov=40\n"
                             "light point pos=0,10,0\nplane refl=0.5 diff=0 spec=1 shininess=200\n";
    const Scene sc = parse_scene(text, "highlight.cfg");
    for (EngineKind engine : {EngineKind::Stream, EngineKind::Recursive}) {
        CAPTURE(engine_name(engine));
        Parallelism par(1);
        const RenderResult r = render_scene(sc, engine, par);
        CHECK(r.counts.primary == P);
        CHECK(r.counts.shadow > 0);
        CHECK(r.counts.shadow < P / 2);
    }
}

// The profile's per-generation rows, worked out by hand. The camera (y = 5) looks straight
// down at a plane at y = 0 that is half mirror, half glass, and sees it in every pixel; a
// mirror plane at y = 20 is above it, a point light at y = 10 between them. Every ray that
// leaves the lower plane upwards is reflected, so it keeps the angle of its camera ray and
// meets the upper plane, and back; a refracted ray goes down through the lower plane and
// meets nothing. Both planes face the light from the side they are seen from (normals face
// the viewer), nothing is between a hit and the light: every hit casts one shadow ray, which
// reaches the light. With P camera rays and depth 3 (generations 0..3 traced, 3 spawns none):
//   0: P rays, all primary, hitting the lower plane: P shadow rays; spawns P up + P down
//   1: 2P rays (0 / P / P): the P reflected hit the upper plane (P shadow rays), the P
//      refracted miss (none); spawns P reflected
//   2: P rays (0 / P / 0), hitting the lower plane: P shadow rays; spawns P up + P down
//   3: 2P rays (0 / P / P): P shadow rays (the upper plane's hits)
// Totals: 6P intersected, 4P shadow rays, as the stage table. The generations' CPU times are
// read by the stage's own timers, so they add up to the stage's exactly.
// Proven against: every slice recorded as generation 0 (stages.h trace_slice).
TEST_CASE("pipeline: per-generation profile of two facing planes, counted by hand") {
    constexpr int W = 24, H = 16;
    constexpr std::uint64_t P = std::uint64_t(W) * H;  // 1 spp
    const std::string text = "image width=" + std::to_string(W) + " height=" + std::to_string(H) +
                             " spp=1 depth=3 degree=5\n"
                             "camera eye=0,5,0 look=0,0,0 up=0,0,-1 fov=40\n"
                             "light point pos=0,10,0\n"
                             "plane refl=0.5 trans=0.5 ior=1.5\n"
                             "plane translate=0,20,0 refl=0.5\n";
    const Scene sc = parse_scene(text, "generations_test.cfg");
    struct Row {
        std::uint64_t rays, primary, reflected, refracted, shadow;
    };
    const Row expected[] = {{P, P, 0, 0, P}, {2 * P, 0, P, P, P}, {P, 0, P, 0, P}, {2 * P, 0, P, P, P}};
    for (int jobs : {1, 2}) {
        CAPTURE(jobs);
        StreamProfile prof;
        Parallelism par(jobs);
        EngineOptions opt;
        opt.profile = &prof;
        const RenderResult r = render_scene(sc, EngineKind::Stream, par, nullptr, opt);
        CHECK(r.counts.primary == P);
        CHECK(r.counts.reflected == 3 * P);
        CHECK(r.counts.refracted == 2 * P);
        CHECK(r.counts.shadow == 4 * P);
        REQUIRE(prof.generations.size() == 4);
        std::uint64_t rays = 0, shadow = 0, intersect_ns = 0, occlusion_ns = 0;
        for (std::size_t d = 0; d < 4; ++d) {
            CAPTURE(d);
            const GenerationFigures& g = prof.generations[d];
            CHECK(g.rays == expected[d].rays);
            CHECK(g.primary == expected[d].primary);
            CHECK(g.reflected == expected[d].reflected);
            CHECK(g.refracted == expected[d].refracted);
            CHECK(g.shadow_rays == expected[d].shadow);
            rays += g.rays, shadow += g.shadow_rays;
            intersect_ns += g.intersect_ns, occlusion_ns += g.occlusion_ns;
        }
        CHECK(rays == 6 * P);
        CHECK(shadow == 4 * P);
        CHECK(prof.stages[int(Stage::Intersect)].rays_in == rays);
        CHECK(prof.stages[int(Stage::Occlusion)].rays_in == shadow);
        CHECK(prof.stages[int(Stage::Occlusion)].rays_out == shadow);
        CHECK(prof.stages[int(Stage::Intersect)].nanoseconds == intersect_ns);
        CHECK(prof.stages[int(Stage::Occlusion)].nanoseconds == occlusion_ns);
        const std::string txt = prof.text();
        CHECK(txt.find("generation") != std::string::npos);
        CHECK(txt.find("(" + std::to_string(P) + "/0/0/0)") != std::string::npos);
        CHECK(txt.find("(0/" + std::to_string(P) + "/" + std::to_string(P) + "/0)") != std::string::npos);
        const std::string js = prof.json();
        CHECK(js.find("\"generations\": [") != std::string::npos);
        CHECK(js.find("{\"generation\": 3, \"rays\": " + std::to_string(2 * P) + ", \"primary\": 0, \"reflected\": " +
                      std::to_string(P) + ", \"refracted\": " + std::to_string(P)) != std::string::npos);
    }
    // Without a profile the render is the same and nothing is recorded (no profile to fill).
    Parallelism par(1);
    const RenderResult plain = render_scene(sc, EngineKind::Stream, par, nullptr, EngineOptions{});
    CHECK(plain.counts.shadow == 4 * P);
}

TEST_CASE("profile: merging grows the generations to the longer list") {
    StreamProfile a, b;
    a.generation(0).rays = 5;
    b.generation(2).rays = 7;
    b.generation(0).shadow_rays = 3;
    a += b;
    REQUIRE(a.generations.size() == 3);
    CHECK(a.generations[0].rays == 5);
    CHECK(a.generations[0].shadow_rays == 3);
    CHECK(a.generations[1].rays == 0);
    CHECK(a.generations[2].rays == 7);
}
