// The command line's job path (cli/job.cpp, cli/picture.cpp) called in-process on one parsed
// scene: the scene is immutable (scene/scene.h), so any number of jobs render it, each to
// its own output, and a job's set-up lets go of nothing another job reads.
#include <doctest/doctest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <string>

#include "cli/cli.h"
#include "image/image_io.h"

namespace fs = std::filesystem;
using namespace streamrt;

namespace {

struct TempDir {
    fs::path path = fs::temp_directory_path() / ("streamrt_cli_job_" + std::to_string(::getpid()));
    TempDir() { fs::create_directories(path); }
    ~TempDir() { fs::remove_all(path); }
};

const char* kScene =
    "image width=40 height=30 spp=2 depth=2 degree=5 output=scene_own.pfm\n"
    "camera eye=0,2,7 look=0,0.5,0 fov=40\n"
    "light point pos=-4,7,6\n"
    "plane color=0.9,0.9,0.9 checker=0.2,0.2,0.2 cell=1\n"
    "sphere color=0.9,0.2,0.1 refl=0.3 scale=0.7 translate=-1,0.7,0\n"
    "cube color=0.2,0.4,0.9 scale=0.5 translate=1.2,0.5,0\n";

/// Renders `scene` through the command line's job path (make_job, render_picture) with -o `out`.
void render_through_cli(const std::shared_ptr<const Scene>& scene, cli::Options opt, const fs::path& out,
                        const std::string& engine) {
    opt.output = out.string();
    opt.engine = engine;
    cli::Job job = cli::make_job(opt, scene, true, true);
    Parallelism par(2);
    SceneBundle bundle;
    std::unique_ptr<PreparedRender> prepared;
    REQUIRE(cli::render_picture(opt, job, par, bundle, prepared) == 0);
    CHECK(!job.scene);  // the job let go of the scene once its engine was prepared
}

}  // namespace

// Proven against: cli/job.cpp's prepare() emptying the scene's object records again (through a
// const_cast) once the stream engine is prepared: the second job renders a scene without
// objects, and its file is the background only.
TEST_CASE("cli job: one parsed scene rendered twice with different -o writes both files, both right") {
    TempDir dir;
    const fs::path path = dir.path / "s.cfg";
    std::ofstream(path) << kScene;
    const auto scene = std::make_shared<const Scene>(load_scene(path.string()));
    const std::size_t objects = scene->objects.size();
    cli::Options opt;
    opt.scene_path = path.string();
    opt.quiet = true;
    opt.jobs = 2;
    Parallelism par(2);
    for (const std::string engine : {"stream", "recursive"}) {
        CAPTURE(engine);
        const fs::path a = dir.path / (engine + "_a.pfm"), b = dir.path / (engine + "_b.pfm");
        render_through_cli(scene, opt, a, engine);
        render_through_cli(scene, opt, b, engine);
        REQUIRE(fs::exists(a));
        REQUIRE(fs::exists(b));
        const EngineKind kind = engine == "stream" ? EngineKind::Stream : EngineKind::Recursive;
        const Scene fresh = load_scene(path.string());  // read again, rendered directly
        const Framebuffer expected = render_scene(fresh, kind, par).image;
        CHECK(read_image(a.string()).rgb == expected.rgb);
        CHECK(read_image(b.string()).rgb == expected.rgb);
    }
    // The scene is as read: its objects, and its own output name (the -o went to the jobs).
    CHECK(scene->objects.size() == objects);
    CHECK(scene->settings.output == "scene_own.pfm");
    CHECK(!fs::exists(dir.path / "scene_own.pfm"));
}
