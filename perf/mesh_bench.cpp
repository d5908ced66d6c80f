// Timing program for triangle meshes (docs/performance.md, "### Meshes"). Not a test.
//
//   mesh_bench [RINGS SEGMENTS] [-j J]
//
// Generates a UV sphere of 2 * SEGMENTS * (RINGS - 1) triangles (default 501 x 1000:
// 1 000 000 triangles), reports its build time and memory per triangle, then renders the
// same view (1280x720, 1 spp, the sphere filling most of the image) of the mesh and of the
// analytic unit sphere with both engines on J threads (default 1: per core), at degree 0
// (primary rays only) and degree 5 (primary + shadow rays, one light), best of 3.
#include <cstdio>
#include <cstdlib>
#include <string>

#include "bench_clock.h"
#include "mesh/mesh.h"
#include "parallel/parallelism.h"
#include "driver/render.h"

using namespace streamrt;
using streamrt::perf::now;

namespace {

Scene view_of(const Object& o, const std::shared_ptr<const Mesh>& mesh, int degree, int width, int height) {
    Scene s;
    if (mesh) s.meshes.push_back(mesh);  // Object::mesh 0
    s.settings.width = width;
    s.settings.height = height;
    s.settings.spp = 1;
    s.settings.depth = 0;
    s.settings.degree = degree;
    s.settings.background = {0.1, 0.1, 0.15};
    s.camera.look_at = true;
    s.camera.eye = {0.4, 0.8, 3.2};
    s.camera.look = {0, 0, 0};
    s.camera.fov = 45;
    s.lights.push_back({LightKind::Point, {3, 5, 4}, {0, -1, 0}, {1, 1, 1}, 30});
    Object plane;
    plane.kind = ShapeKind::Plane;
    plane.md = glm::dmat4x3(translate_matrix({0, -1, 0}));
    s.add_object(plane, Material{}, {});
    s.add_object(o, Material{}, {});
    return s;
}

}  // namespace

int main(int argc, char** argv) {
    int rings = 501, segments = 1000, jobs = 1;
    int pos = 0;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "-j" && i + 1 < argc) jobs = std::atoi(argv[++i]);
        else if (pos == 0) rings = std::atoi(argv[i]), ++pos;
        else segments = std::atoi(argv[i]);
    }
    double t0 = now();
    const MeshData d = uv_sphere(rings, segments);
    const double gen = now() - t0;
    t0 = now();
    const auto mesh = Mesh::build("uv_sphere", d.positions, d.triangles);
    const double build = now() - t0;
    const double n = double(mesh->triangle_count());
    std::printf("mesh: %zu triangles, %zu vertices (generated in %.2f s)\n", mesh->triangle_count(),
                d.positions.size() / 3, gen);
    std::printf("build (boxes, SAH BVH, leaf-order copy, normals): %.2f s; %zu wide nodes\n", build,
                mesh->bvh.stats.wide_nodes);
    const double vertices_b = double(mesh->positions.size() * sizeof(float)), idx = double(mesh->index.size() * 4),
                 nrm = double(mesh->vertex_normals.size() * sizeof(float)),
                 nodes = double(mesh->bvh.memory_bytes()),
                 blocks = double(mesh->blocks.size() * sizeof(TriangleBlock) + mesh->block_of.size() * 4);
    std::printf("memory: %.1f bytes/triangle (vertex positions %.1f, vertex numbers %.1f, vertex normals %.1f, "
                "BVH nodes %.1f, triangle blocks and their map %.1f)\n",
                double(mesh->memory_bytes()) / n, vertices_b / n, idx / n, nrm / n, nodes / n, blocks / n);

    Object sphere;
    sphere.kind = ShapeKind::Sphere;
    Object m;
    m.kind = ShapeKind::Mesh;
    m.param = 1.0;  // smooth
    Parallelism par(jobs);
    std::printf("\nrender 1280x720, 1 spp, -j %d, best of 3 (recursive engine at 640x360)\n", jobs);
    std::printf("%-8s %-7s %-10s %10s %12s %16s\n", "object", "degree", "engine", "seconds", "Mrays/s", "primary Mrays/s");
    for (int degree : {0, 5})
        for (const Object* o : {&sphere, &m})
            for (EngineKind e : {EngineKind::Stream, EngineKind::Recursive}) {
                const bool rec = e == EngineKind::Recursive;
                const Scene s = view_of(*o, o == &m ? mesh : nullptr, degree, rec ? 640 : 1280, rec ? 360 : 720);
                double best = 1e30;
                RenderResult r;
                for (int k = 0; k < 3; ++k) {
                    r = render_scene(s, e, par);
                    best = std::min(best, r.seconds);
                }
                const double rays = double(r.counts.primary + r.counts.shadow + r.counts.reflected + r.counts.refracted);
                std::printf("%-8s %-7d %-10s %10.3f %12.2f %16.2f\n", o == &sphere ? "sphere" : "mesh", degree,
                            engine_name(e), best, rays / best * 1e-6, double(r.counts.primary) / best * 1e-6);
            }
    return 0;
}
