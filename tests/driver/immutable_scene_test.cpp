// The parsed scene is immutable (scene/scene.h, driver/render_job.h): a job holds it as
// shared_ptr<const Scene>, its overrides live in the job's settings, an animated frame is a
// new scene made from it, and a prepared render holds what it reads, so a job may let go of
// the scene once its engine is prepared.
#include <doctest/doctest.h>

#include <cstring>
#include <memory>
#include <string>
#include <type_traits>

#include "driver/render.h"
#include "driver/render_job.h"
#include "scene/animation.h"
#include "scene/parser.h"

using namespace streamrt;

// ---- compile time: nothing a job or a set-up is given can change the scene ----
static_assert(std::is_same_v<decltype(RenderJob::scene), std::shared_ptr<const Scene>>);
static_assert(std::is_const_v<std::remove_reference_t<decltype(*std::declval<RenderJob&>().scene)>>);
static_assert(std::is_invocable_r_v<RenderJob, decltype(&build_render_job), std::shared_ptr<const Scene>,
                                    const RenderOverrides&, bool>);
static_assert(std::is_invocable_v<decltype(&prepare_job), const RenderJob&, EngineKind, int>);
static_assert(std::is_invocable_v<decltype(&update_job_frame), PreparedRender&, const RenderJob&, int, int>);
static_assert(std::is_invocable_r_v<std::shared_ptr<const Scene>, decltype(&scene_at_frame),
                                    const std::shared_ptr<const Scene>&, int>);
static_assert(requires(std::shared_ptr<const Scene> s, const RenderSettings& r, PreparedRender& p, FrameChange c) {
    prepare_render(s, r, EngineKind::Stream);
    p.update(s, c);
});

namespace {

// A ball, a light and the camera keyed over frames 0..4; the ball also turns.
const char* kAnimated =
    "image width=48 height=32 spp=2 depth=2 degree=5\n"
    "camera name=cam eye=0,2,8 look=0,0.5,0 fov=40\n"
    "light point name=sun pos=-4,7,6\n"
    "light rect pos=2,5,2 u=1,0,0 v=0,0,1 samples=4\n"
    "plane color=0.9,0.9,0.9 checker=0.2,0.2,0.2 cell=1\n"
    "sphere color=0.2,0.4,0.9 refl=0.3 scale=0.7 translate=1.5,0.7,-1\n"
    "cube name=ball color=0.9,0.2,0.1 scale=0.5\n"
    "key ball frame=0 translate=-2,0.5,0\n"
    "key ball frame=4 translate=1,1.5,1 rotate=0,1,0,60\n"
    "key sun frame=0 pos=-4,7,6\n"
    "key sun frame=4 pos=4,6,6\n"
    "key cam frame=0 eye=0,2,8\n"
    "key cam frame=4 eye=3,2.5,7\n";

Framebuffer render(PreparedRender& p) {
    Parallelism par(2);
    return render_prepared(p, par).image;
}

/// The scene's state that frames and overrides would change, byte for byte.
bool same_state(const Scene& a, const Scene& b) {
    const auto bytes = [](const auto& v, const auto& w) {
        return v.size() == w.size() && std::memcmp(v.data(), w.data(), v.size() * sizeof(v[0])) == 0;
    };
    return bytes(a.objects, b.objects) && a.lights.size() == b.lights.size() &&
           a.lights[0].pos == b.lights[0].pos && a.lights[1].samples == b.lights[1].samples &&
           a.camera.eye == b.camera.eye && a.settings.spp == b.settings.spp && a.settings.output == b.settings.output;
}

}  // namespace

TEST_CASE("immutable scene: overrides go to the job's settings, the scene keeps its own") {
    const auto scene = std::make_shared<const Scene>(parse_scene(kAnimated, "t.cfg"));
    const Scene as_read = *scene;
    RenderOverrides o;
    REQUIRE(set_override(o, "spp", "3"));
    REQUIRE(set_override(o, "light_samples", "9"));
    o.output = "elsewhere.png";
    const RenderJob job = build_render_job(scene, o, false);
    CHECK(job.scene == scene);  // shared, not copied
    CHECK(job.render_settings.spp == 3);
    CHECK(job.render_settings.light_samples == 9);
    CHECK(rendered_light(scene->lights[1], job.render_settings).samples == 9);
    CHECK(rendered_light(scene->lights[0], job.render_settings).samples == scene->lights[0].samples);
    CHECK(job.render_settings.output == "elsewhere.png");
    CHECK(same_state(*scene, as_read));
    // A second job from the same scene sees the scene's own values.
    const RenderJob plain = build_render_job(scene, {}, false);
    CHECK(plain.render_settings.spp == 2);
    CHECK(plain.render_settings.light_samples == 0);
    CHECK(plain.render_settings.output == as_read.settings.output);
}

// Proven against: scene_at_frame putting the base scene itself at the frame (set_frame on
// const_cast<Scene&>(*base), returned): the picture of frame 0 after frame 2 is frame 2's,
// and the scene as read has moved.
TEST_CASE("immutable scene: frame 2 then frame 0 gives frame 0's picture, bit for bit, in both engines") {
    const auto scene = std::make_shared<const Scene>(parse_scene(kAnimated, "t.cfg"));
    const Scene as_read = *scene;
    const RenderJob job = build_render_job(scene, {}, false);
    for (const EngineKind engine : {EngineKind::Stream, EngineKind::Recursive}) {
        CAPTURE(std::string(engine_name(engine)));
        // Frame 0 rendered first, from a scene of its own.
        const auto own = std::make_shared<const Scene>(parse_scene(kAnimated, "t.cfg"));
        const RenderJob other = build_render_job(own, {}, false);
        const Framebuffer first0 = render(*prepare_job(other, engine, 0));
        const auto p = prepare_job(job, engine, 2);
        const Framebuffer frame2 = render(*p);
        CHECK(frame2.rgb != first0.rgb);
        update_job_frame(*p, job, 2, 0);
        CHECK(render(*p).rgb == first0.rgb);
        // And back again: frame 2 from frame 0 is frame 2 made afresh.
        update_job_frame(*p, job, 0, 2);
        CHECK(render(*p).rgb == frame2.rgb);
        CHECK(same_state(*scene, as_read));
        CHECK(render(*prepare_job(job, engine, 0)).rgb == first0.rgb);
    }
    CHECK(scene_at_frame(scene, 0) == scene);  // frame 0 is the scene as read: no copy
    CHECK(scene_at_frame(scene, 2) != scene);  // another frame is a new scene
}

TEST_CASE("immutable scene: a job lets go of its scene, the set-up holds what it reads, nothing dangles") {
    // Meshes and textures: the stream engine holds them itself, the recursive engine the scene.
    const std::string path = std::string(STREAMRT_SOURCE_DIR) + "/scenes/textured.cfg";
    RenderOverrides o;
    REQUIRE(set_override(o, "width", "64"));
    REQUIRE(set_override(o, "height", "48"));
    for (const EngineKind engine : {EngineKind::Stream, EngineKind::Recursive}) {
        CAPTURE(std::string(engine_name(engine)));
        const Framebuffer expected = render(*prepare_job(build_render_job(
            std::make_shared<const Scene>(load_scene(path)), o, false), engine, -1));
        RenderJob job = build_render_job(std::make_shared<const Scene>(load_scene(path)), o, false);
        REQUIRE(!job.scene->meshes.empty());
        REQUIRE(!job.scene->textures.empty());
        const std::weak_ptr<const Scene> seen = job.scene;
        const auto prepared = prepare_job(job, engine, -1);
        job.scene.reset();  // the job's reference was the last one but the engine's
        CHECK(seen.expired() == !prepared->reads_scene_objects());
        CHECK(prepared->reads_scene_objects() == (engine == EngineKind::Recursive));
        CHECK(render(*prepared).rgb == expected.rgb);
    }
}
