// Timing program for the mesh walks per ray kind (docs/performance.md, "### Meshes"). Not a test.
//
//   mesh_walk_bench [--isa LEVEL] [--reps N] [--lanes L,L,...]
//
// Two meshes: the 1M-triangle UV sphere of mesh_bench (501 x 1000) and an irregular 200k-
// triangle mesh (a 317 x 317 UV sphere with lumps and random vertex jitter: triangles of
// every size and shape). One view (1280x720, the camera of mesh_bench), primary rays in 4x4
// pixel tiles; at each primary hit, in the same order, a shadow ray to a point light (any
// hit), a mirror-reflected ray, a glass-refracted ray (index 1.5) and a diffuse ray (uniform
// over the hemisphere: incoherent) (closest hit): the ray sets of perf/mesh_rays.h. Each
// stream runs through the level's flat mesh kernel (KernelTable closest/any[Mesh], one
// thread) with MeshView::single_ray_lanes = each value of --lanes (0: packet walk only; 64:
// single-ray walk only; between: the hybrid), median of N runs (default 5), in Mrays/s. Row
// "scene1": the same streams through the scene hierarchy's single-ray traversal (the mesh one
// leaf object; its mesh walk is the single-ray walk).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "kernels/kernel_table.h"
#include "mesh_rays.h"
#include "mesh/mesh.h"
#include "scene/scene_bvh.h"
#include "stream/stream_accel.h"
#include "simd/lanes.h"

using namespace streamrt;
using namespace streamrt::perf;

namespace {

MeshData irregular_mesh() {
    MeshData m = uv_sphere(317, 317);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> jitter(-0.3f, 0.3f);
    const float step = 3.14159265f / 317.f;
    for (std::size_t v = 0; v < m.positions.size(); v += 3) {
        float* p = &m.positions[v];
        const float lump = 1.f + 0.12f * std::sin(7 * p[0]) * std::sin(5 * p[1]) * std::sin(6 * p[2]);
        for (int a = 0; a < 3; ++a) p[a] = p[a] * lump + jitter(rng) * step;
    }
    return m;
}

/// The stream through the scene hierarchy's single-ray walk (AccelConfig Traversal::Single),
/// which meets the mesh as a leaf object.
double scene_single_mrays(const Stream& st, bool any, const KernelTable& kt, const StreamAccel& sa, int reps) {
    std::vector<double> secs;
    simd::AlignedVec<float> t(st.t_max.size()), bu(t.size()), bv(t.size());
    simd::AlignedVec<std::int32_t> id(t.size()), prim(t.size());
    for (int r = 0; r < reps; ++r) {
        std::copy(st.t_max.begin(), st.t_max.end(), t.begin());
        RayView v = st.view(t.data());
        const double t0 = now();
        if (any) {
            sa.any(kt, v);
        } else {
            v.prim = prim.data(), v.bu = bu.data(), v.bv = bv.data();
            sa.closest(kt, v, id.data(), false);
        }
        secs.push_back(now() - t0);
    }
    std::sort(secs.begin(), secs.end());
    return double(st.count) / secs[secs.size() / 2] * 1e-6;
}

}  // namespace

int main(int argc, char** argv) {
    Isa isa = best_isa();
    int reps = 5;
    std::vector<std::uint32_t> lanes{0, 1, 2, 4, 8, 64};
    for (int i = 1; i + 1 < argc; i += 2) {
        const std::string a = argv[i];
        if (a == "--isa" && !parse_isa(argv[i + 1], isa)) return std::fprintf(stderr, "unknown level\n"), 2;
        if (a == "--reps") reps = std::max(1, std::atoi(argv[i + 1]));
        if (a == "--lanes") {
            lanes.clear();
            for (const char* p = argv[i + 1]; *p;) {
                lanes.push_back(std::uint32_t(std::strtoul(p, const_cast<char**>(&p), 10)));
                if (*p == ',') ++p;
            }
        }
    }
    const KernelTable& kt = kernel_table(isa);
    std::printf("level %s (%d-lane packets), one thread, median of %d, Mrays/s; lanes = single_ray_lanes "
                "(0 packet, 64 single)\n",
                kt.name, kt.float_lanes, reps);
    struct Named {
        const char* name;
        MeshData data;
    };
    for (const Named& nm : {Named{"uv_sphere", uv_sphere(501, 1000)}, Named{"irregular", irregular_mesh()}}) {
        const auto mesh = Mesh::build(nm.name, nm.data.positions, nm.data.triangles);
        std::printf("\n%s: %zu triangles, %.1f bytes/triangle (triangle blocks %.1f)\n", nm.name,
                    mesh->triangle_count(), double(mesh->memory_bytes()) / double(mesh->triangle_count()),
                    double(mesh->blocks.size() * sizeof(TriangleBlock) + mesh->block_of.size() * 4) /
                        double(mesh->triangle_count()));
        ObjectXf xf{};
        xf.m[0] = xf.m[5] = xf.m[10] = 1.f;
        xf.mesh = &mesh->view();
        const Streams s = make_streams(*mesh, kt, xf);
        std::printf("%-6s %10s %10s %10s %10s %10s\n", "lanes", "primary", "shadow", "mirror", "glass", "diffuse");
        for (std::uint32_t l : lanes) {
            const auto m = mesh->with_single_ray_lanes(l);
            ObjectXf x = xf;
            x.mesh = &m->view();
            std::printf("%-6u %10.2f %10.2f %10.2f %10.2f %10.2f\n", l, mrays(s.primary, false, kt, x, reps),
                        mrays(s.shadow, true, kt, x, reps), mrays(s.mirror, false, kt, x, reps),
                        mrays(s.glass, false, kt, x, reps), mrays(s.diffuse, false, kt, x, reps));
            std::fflush(stdout);
        }
        Scene scene;
        Object o;
        o.kind = ShapeKind::Mesh;
        o.mesh = 0;
        o.md = glm::dmat4x3(glm::dmat4(1.0));
        scene.meshes.push_back(mesh);
        scene.add_object(o);
        accel::AccelConfig single;
        single.mode = accel::AccelMode::Bvh;
        single.primary = single.secondary = single.shadow = accel::Traversal::Single;
        const StreamAccel sa(scene, accel::SceneBvh::build(scene), single);
        std::printf("%-6s %10.2f %10.2f %10.2f %10.2f %10.2f\n", "scene1", scene_single_mrays(s.primary, false, kt, sa, reps),
                    scene_single_mrays(s.shadow, true, kt, sa, reps), scene_single_mrays(s.mirror, false, kt, sa, reps),
                    scene_single_mrays(s.glass, false, kt, sa, reps), scene_single_mrays(s.diffuse, false, kt, sa, reps));
    }
    return 0;
}
