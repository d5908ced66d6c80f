// -j holds while a scene is read: the loops that load a mesh (its triangles, its hierarchy)
// run in the reader's threads, not in all the machine's cores (issue 11, item 9).
#include <doctest/doctest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "parallel/parallelism.h"
#include "scene/parser.h"

using namespace streamrt;
namespace fs = std::filesystem;

namespace {

/// A scene naming one OBJ grid of 2 x n x n triangles, written under a fresh folder.
fs::path write_mesh_scene(int n) {
    const fs::path dir = fs::temp_directory_path() / ("streamrt_load_jobs_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    std::ofstream obj(dir / "grid.obj");
    for (int y = 0; y <= n; ++y)
        for (int x = 0; x <= n; ++x) obj << "v " << x << " " << (x * y) % 7 * 0.01 << " " << y << "\n";
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            const int a = y * (n + 1) + x + 1, b = a + 1, c = a + n + 1, d = c + 1;
            obj << "f " << a << " " << b << " " << d << "\nf " << a << " " << d << " " << c << "\n";
        }
    std::ofstream(dir / "scene.cfg") << "mesh file=grid.obj scale=0.01\n";
    return dir;
}

}  // namespace

TEST_CASE("load_scene: the loops loading a mesh use at most -j threads") {
    // 2 x 300 x 300 = 180000 triangles: the mesh loops run in 11 pieces of 16384 and its
    // hierarchy build forks, so with all cores allowed both of this machine's would join.
    const fs::path dir = write_mesh_scene(300);
    for (int jobs : {1, 2}) {
        CAPTURE(jobs);
        ThreadProbe probe;
        const Scene s = load_scene((dir / "scene.cfg").string(), jobs);
        CHECK(s.meshes.size() == 1);
        CHECK(probe.threads() >= 1);  // the loops ran under the probe
        CHECK(probe.threads() <= std::size_t(jobs));
    }
    {
        // Text in memory as well.
        ThreadProbe probe;
        ReadOptions one;
        one.jobs = 1;
        parse_scene("mesh file=grid.obj\n", (dir / "inline.cfg").string(), one);
        CHECK(probe.threads() == 1);
    }
    fs::remove_all(dir);
}
