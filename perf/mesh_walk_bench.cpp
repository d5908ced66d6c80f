// Timing program for the mesh walks per ray kind (docs/performance.md, "### Meshes"). Not a test.
//
//   mesh_walk_bench [--isa LEVEL] [--reps N] [--lanes L,L,...]
//
// Two meshes: the 1M-triangle UV sphere of mesh_bench (501 x 1000) and an irregular 200k-
// triangle mesh (a 317 x 317 UV sphere with lumps and random vertex jitter: triangles of
// every size and shape). One view (1280x720, the camera of mesh_bench), primary rays in 4x4
// pixel tiles; at each primary hit, in the same order, a shadow ray to a point light (any
// hit), a mirror-reflected ray, a glass-refracted ray (index 1.5) and a diffuse ray (uniform
// over the hemisphere: incoherent) (closest hit). Each
// stream runs through the level's flat mesh kernel (KernelTable closest/any[Mesh], one
// thread) with MeshView::single_ray_lanes = each value of --lanes (0: packet walk only; 64:
// single-ray walk only; between: the hybrid), median of N runs (default 5), in Mrays/s. Row
// "scene1": the same streams through the scene hierarchy's single-ray traversal (the mesh one
// leaf object; its mesh walk is the single-ray walk).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "kernels/kernel_table.h"
#include "mesh/mesh.h"
#include "scene/scene_bvh.h"
#include "stream/stream_accel.h"
#include "simd/lanes.h"

using namespace streamrt;

namespace {

double now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

/// A ray stream padded to 16 lanes with inactive rays (t_max = 0).
struct Stream {
    simd::AlignedVec<float> ox, oy, oz, dx, dy, dz, t_max;
    std::size_t count = 0;
    void add(const Vec3f& o, const Vec3f& d, float t) {
        ox.push_back(o.x), oy.push_back(o.y), oz.push_back(o.z);
        dx.push_back(d.x), dy.push_back(d.y), dz.push_back(d.z);
        t_max.push_back(t);
        ++count;
    }
    void pad() {
        const std::size_t n = count;
        while (ox.size() % 16) add({0, 0, 0}, {0, 0, 1}, 0.f);
        count = n;
    }
    RayView view(float* t) const { return {count, ox.data(), oy.data(), oz.data(), dx.data(), dy.data(), dz.data(), t}; }
};

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

struct Streams {
    Stream primary, shadow, mirror, glass, diffuse;
};

/// The four ray streams of the view: primary rays traced once (packet walk) for the hits.
Streams make_streams(const Mesh& mesh, const KernelTable& kt, const ObjectXf& xf) {
    Streams s;
    const int w = 1280, h = 720;
    const Vec3f eye{0.4f, 0.8f, 3.2f};
    const Vec3f fwd = normalize(Vec3f{0, 0, 0} - eye);
    const Vec3f right = normalize(cross(fwd, Vec3f{0, 1, 0})), up = cross(right, fwd);
    const float scale = std::tan(22.5f * 3.14159265f / 180.f);
    for (int ty = 0; ty < h; ty += 4)
        for (int tx = 0; tx < w; tx += 4)
            for (int y = ty; y < ty + 4; ++y)
                for (int x = tx; x < tx + 4; ++x) {
                    const float px = (2.f * (x + 0.5f) / w - 1.f) * scale * w / h, py = (1.f - 2.f * (y + 0.5f) / h) * scale;
                    s.primary.add(eye, normalize(fwd + px * right + py * up), 1e30f);
                }
    s.primary.pad();
    simd::AlignedVec<float> t(s.primary.t_max), bu(t.size()), bv(t.size());
    simd::AlignedVec<std::int32_t> id(t.size(), -1), prim(t.size(), -1);
    RayView v = s.primary.view(t.data());
    v.prim = prim.data(), v.bu = bu.data(), v.bv = bv.data();
    kt.closest[int(ShapeKind::Mesh)](v, id.data(), &xf, 1);
    const Vec3f light{3, 5, 4};
    std::mt19937 rng(3);
    std::normal_distribution<float> gauss(0.f, 1.f);
    for (std::size_t i = 0; i < s.primary.count; ++i) {
        if (id[i] != 0) continue;
        const Vec3f o{s.primary.ox[i], s.primary.oy[i], s.primary.oz[i]}, d{s.primary.dx[i], s.primary.dy[i],
                                                                                s.primary.dz[i]};
        const Vec3f p = o + t[i] * d;
        const float* q = &mesh.tri[9 * std::size_t(prim[i])];
        Vec3f n = normalize(cross(Vec3f{q[3] - q[0], q[4] - q[1], q[5] - q[2]}, Vec3f{q[6] - q[0], q[7] - q[1], q[8] - q[2]}));
        if (dot(n, d) > 0) n = -n;
        const Vec3f out = p + 1e-4f * n, in = p - 1e-4f * n;
        const Vec3f to_light = light - out;
        const float dist = length(to_light);
        s.shadow.add(out, (1.f / dist) * to_light, dist);
        s.mirror.add(out, d - 2.f * dot(d, n) * n, 1e30f);
        const float eta = 1.f / 1.5f, c = -dot(d, n), k = 1.f - eta * eta * (1.f - c * c);
        s.glass.add(in, normalize(eta * d + (eta * c - std::sqrt(k)) * n), 1e30f);
        Vec3f r{gauss(rng), gauss(rng), gauss(rng)};  // uniform over the outer hemisphere
        if (dot(r, n) < 0) r = -r;
        s.diffuse.add(out, normalize(r), 1e30f);
    }
    s.shadow.pad();
    s.mirror.pad();
    s.glass.pad();
    s.diffuse.pad();
    return s;
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

double mrays(const Stream& st, bool any, const KernelTable& kt, const ObjectXf& xf, int reps) {
    std::vector<double> secs;
    simd::AlignedVec<float> t(st.t_max.size()), bu(t.size()), bv(t.size());
    simd::AlignedVec<std::int32_t> id(t.size()), prim(t.size());
    for (int r = 0; r < reps; ++r) {
        std::copy(st.t_max.begin(), st.t_max.end(), t.begin());
        RayView v = st.view(t.data());
        const double t0 = now();
        if (any) {
            kt.any[int(ShapeKind::Mesh)](v, &xf, 1);
        } else {
            v.prim = prim.data(), v.bu = bu.data(), v.bv = bv.data();
            kt.closest[int(ShapeKind::Mesh)](v, id.data(), &xf, 1);
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
