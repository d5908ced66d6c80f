// Embree 3 against streamrt's mesh kernels on the same rays (docs/performance.md, "Against
// POV-Ray and Embree"). Not a test; built only when CMake finds Embree 3 (perf/CMakeLists.txt).
//
//   embree_rays [--reps N] [--isa LEVEL] [--quality medium|high] [--rays KIND,...] MESH.{obj,ply} ...
//   embree_rays [--reps N] [--isa LEVEL] [--quality medium|high] --spheres N
//
// --spheres N: instead of meshes, the field of N random spheres of perf/bvh_bench (perf/sphere_field.h:
// camera rays in the stream engine's 16x16 tiles, mirror-reflected and shadow rays from their hits),
// as an Embree scene of point spheres (RTC_GEOMETRY_TYPE_SPHERE_POINT: centre and radius) against
// the stream engine's hierarchy kernels over its canonical spheres placed by their matrices
// (AccelKernelTable: packet and single-ray walks; the plane is outside both).
//
// --rays keeps only the listed ray sets (primary, shadow, mirror, glass, diffuse), e.g. to
// profile one of them with perf. --shuffle traces every mesh ray set in a random order (fixed
// seed) instead of screen order: each walk then finds less of its path in cache from the walk
// before, as a renderer's deep rays do.
//
// Each mesh is read by streamrt's own reader (load_mesh_file) and built twice: streamrt's mesh
// (its 8-wide hierarchy, as a scene uses it) and an Embree scene of the same triangles, in the
// same order (RTC_GEOMETRY_TYPE_TRIANGLE, RTC_BUILD_QUALITY_HIGH for the scene and the
// geometry, a device with threads=1). High quality is Embree's SAH build with spatial splits;
// --quality medium is its SAH build without them (what streamrt's builder does). The ray sets are perf/mesh_rays.h's, over a view fitted
// to the mesh's bounds (1280x720 primary rays in 4x4 tiles; from their hits, shadow rays to a
// point light, mirror-reflected rays, rays refracted into the mesh (index 1.5: they travel
// inside it, as a glass mesh's deeper rays do) and, as the incoherent extreme, diffuse rays). Every set
// runs on this one thread, median of N runs (default 5), in Mrays/s:
//   Embree16   rtcIntersect16 / rtcOccluded16 on packets of 16 consecutive rays (a 4x4 pixel
//              tile for primary rays); the packets are filled before the clock starts
//   Embree1    rtcIntersect1 / rtcOccluded1 ray by ray
//   streamrt   the level's flat mesh kernel (KernelTable closest/any[Mesh]) over the stream
//   single     streamrt's single-ray walk alone (every packet handed over at the root; the
//              stream engine's choice for scattered packets of deep rays, --mesh-hybrid)
// ratio = streamrt / Embree16. The numbers of rays hit (or blocked) by each are printed as a
// check that all three traced the same rays.
#include <embree3/rtcore.h>
#include <xmmintrin.h>
#include <pmmintrin.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <limits>
#include <string>
#include <vector>

#include "kernels/kernel_table.h"
#include "mesh/mesh.h"
#include "mesh/ply_reader.h"
#include "mesh_rays.h"
#include "sphere_field.h"

using namespace streamrt;
using namespace streamrt::perf;

namespace {

void embree_error(void*, RTCError code, const char* msg) {
    std::fprintf(stderr, "embree error %d: %s\n", int(code), msg ? msg : "");
    std::exit(1);
}

/// The mesh's triangles as an Embree scene (vertices shared as in the mesh, triangles in the
/// mesh's leaf order, so Embree's primID is streamrt's triangle number).
RTCScene embree_scene(RTCDevice dev, const Mesh& mesh, RTCBuildQuality quality) {
    const std::size_t nt = mesh.triangle_count();
    std::uint32_t nv = 0;
    for (std::uint32_t i : mesh.index) nv = std::max(nv, i + 1);
    RTCScene scene = rtcNewScene(dev);
    rtcSetSceneBuildQuality(scene, quality);
    RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetGeometryBuildQuality(g, quality);
    auto* vb = static_cast<float*>(
        rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), nv));
    auto* ib = static_cast<unsigned*>(
        rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), nt));
    std::fill(vb, vb + 3 * std::size_t(nv), 0.f);
    for (std::size_t t = 0; t < nt; ++t)
        for (int j = 0; j < 3; ++j) {
            const std::uint32_t v = mesh.index[3 * t + j];
            ib[3 * t + j] = v;
            std::memcpy(vb + 3 * std::size_t(v), mesh.corner(t, j), 3 * sizeof(float));
        }
    rtcCommitGeometry(g);
    rtcAttachGeometry(scene, g);
    rtcReleaseGeometry(g);
    rtcCommitScene(scene);
    return scene;
}

struct Result {
    double mrays = 0;
    std::size_t hits = 0;
};

/// rtcIntersect16 / rtcOccluded16 over the stream in packets of 16 consecutive rays.
Result embree16(RTCScene scene, const Stream& st, bool any, int reps) {
    const std::size_t packets = st.ox.size() / 16;
    std::vector<RTCRayHit16> fresh(packets), work(packets);
    simd::AlignedVec<int> valid(st.ox.size());  // 64-byte aligned, as rtcIntersect16 needs
    for (std::size_t p = 0; p < packets; ++p) {
        RTCRayHit16& rh = fresh[p];
        std::memset(&rh, 0, sizeof rh);
        for (int k = 0; k < 16; ++k) {
            const std::size_t i = 16 * p + k;
            rh.ray.org_x[k] = st.ox[i], rh.ray.org_y[k] = st.oy[i], rh.ray.org_z[k] = st.oz[i];
            rh.ray.dir_x[k] = st.dx[i], rh.ray.dir_y[k] = st.dy[i], rh.ray.dir_z[k] = st.dz[i];
            rh.ray.tnear[k] = 0.f;
            rh.ray.tfar[k] = st.t_max[i];
            rh.ray.mask[k] = ~0u;
            rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
            rh.hit.instID[0][k] = RTC_INVALID_GEOMETRY_ID;
            valid[i] = i < st.count && st.t_max[i] > 0 ? -1 : 0;
        }
    }
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    const double sec = median_seconds(reps, [&] {
        std::copy(fresh.begin(), fresh.end(), work.begin());
        const double t0 = now();
        if (any) {
            for (std::size_t p = 0; p < packets; ++p) rtcOccluded16(&valid[16 * p], scene, &ctx, &work[p].ray);
        } else {
            for (std::size_t p = 0; p < packets; ++p) rtcIntersect16(&valid[16 * p], scene, &ctx, &work[p]);
        }
        return now() - t0;
    });
    Result r{double(st.count) / sec * 1e-6, 0};
    for (std::size_t i = 0; i < st.count; ++i) {
        const RTCRayHit16& rh = work[i / 16];
        const int k = int(i % 16);
        if (valid[i]) r.hits += any ? rh.ray.tfar[k] < 0 : rh.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID;
    }
    return r;
}

/// rtcIntersect1 / rtcOccluded1 ray by ray.
Result embree1(RTCScene scene, const Stream& st, bool any, int reps) {
    std::vector<RTCRayHit> fresh(st.count), work(st.count);
    for (std::size_t i = 0; i < st.count; ++i) {
        RTCRayHit& rh = fresh[i];
        std::memset(&rh, 0, sizeof rh);
        rh.ray.org_x = st.ox[i], rh.ray.org_y = st.oy[i], rh.ray.org_z = st.oz[i];
        rh.ray.dir_x = st.dx[i], rh.ray.dir_y = st.dy[i], rh.ray.dir_z = st.dz[i];
        rh.ray.tnear = 0.f;
        rh.ray.tfar = st.t_max[i];
        rh.ray.mask = ~0u;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    }
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    const double sec = median_seconds(reps, [&] {
        std::copy(fresh.begin(), fresh.end(), work.begin());
        const double t0 = now();
        if (any) {
            for (RTCRayHit& rh : work) rtcOccluded1(scene, &ctx, &rh.ray);
        } else {
            for (RTCRayHit& rh : work) rtcIntersect1(scene, &ctx, &rh);
        }
        return now() - t0;
    });
    Result r{double(st.count) / sec * 1e-6, 0};
    for (const RTCRayHit& rh : work) r.hits += any ? rh.ray.tfar < 0 : rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
    return r;
}

/// The spheres as Embree point spheres (x, y, z, radius), in the scene's order.
RTCScene embree_spheres(RTCDevice dev, const std::vector<SphereRec>& sph, RTCBuildQuality quality) {
    RTCScene scene = rtcNewScene(dev);
    rtcSetSceneBuildQuality(scene, quality);
    RTCGeometry g = rtcNewGeometry(dev, RTC_GEOMETRY_TYPE_SPHERE_POINT);
    rtcSetGeometryBuildQuality(g, quality);
    auto* vb = static_cast<float*>(
        rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), sph.size()));
    for (std::size_t i = 0; i < sph.size(); ++i) {
        vb[4 * i] = float(sph[i].x), vb[4 * i + 1] = float(sph[i].y), vb[4 * i + 2] = float(sph[i].z);
        vb[4 * i + 3] = float(sph[i].r);
    }
    rtcCommitGeometry(g);
    rtcAttachGeometry(scene, g);
    rtcReleaseGeometry(g);
    rtcCommitScene(scene);
    return scene;
}

/// The chunks of a ray set as one stream padded to 16 lanes (the harness's form for Embree).
template <class Chunk>
Stream flat_stream(const std::vector<Chunk>& set) {
    Stream st;
    for (const Chunk& c : set)
        for (std::size_t k = 0; k < c.count; ++k) st.add({c.ox[k], c.oy[k], c.oz[k]}, {c.dx[k], c.dy[k], c.dz[k]}, c.t_max[k]);
    st.pad();
    return st;
}

/// The sphere field: Embree16, Embree1 and the stream engine's hierarchy kernels on the same rays.
int sphere_field(RTCDevice dev, Isa isa, std::size_t n, int reps, RTCBuildQuality quality) {
    std::vector<SphereRec> sph;
    const Scene s = random_spheres(n, &sph);
    const KernelTable& kt = kernel_table(isa);
    const AccelKernelTable& at = accel_kernel_table(isa);
    const double t0 = now();
    StreamAccel sa(s, accel::SceneBvh::build(s), accel::AccelConfig{});
    const double t_ours = now() - t0;
    SphereRays sets = sphere_rays(s, sph, sa, kt);
    const double t1 = now();
    RTCScene scene = embree_spheres(dev, sph, quality);
    const double t_embree = now() - t1;
    auto sb = accel::SceneBvh::build(s);
    const std::vector<KernelObject> prims = leaf_objects(s, *sb);
    const AccelView view{sb->bvh.nodes.data(), prims.data()};
    std::printf("\n%zu random spheres (perf/bvh_bench's field); streamrt hierarchy %.2f s, Embree build (%s quality, "
                "1 thread) %.2f s; 1280x720 camera rays\n",
                n, t_ours, quality == RTC_BUILD_QUALITY_HIGH ? "high" : "medium", t_embree);
    std::printf("%-9s %9s %10s %10s %10s %7s %10s   %s\n", "rays", "count", "Embree16", "Embree1", "streamrt", "ratio",
                "single", "hits: Embree16 / Embree1 / streamrt");
    const auto row = [&](const char* name, const Stream& flat, bool any, SetTiming ours, SetTiming single) {
        const Result e16 = embree16(scene, flat, any, reps), e1 = embree1(scene, flat, any, reps);
        std::printf("%-9s %9zu %10.2f %10.2f %10.2f %6.2fx %10.2f   %zu / %zu / %zu\n", name, flat.count, e16.mrays,
                    e1.mrays, ours.mrays, ours.mrays / e16.mrays, single.mrays, e16.hits, e1.hits, ours.hits);
        std::fflush(stdout);
    };
    row("primary", flat_stream(sets.primary), false, time_closest(sets.primary, at.closest_packet, view, reps),
        time_closest(sets.primary, at.closest_single, view, reps));
    row("shadow", flat_stream(sets.shadow), true, time_any(sets.shadow, at.any_packet, view, reps),
        time_any(sets.shadow, at.any_single, view, reps));
    row("reflected", flat_stream(sets.reflected), false, time_closest(sets.reflected, at.closest_packet, view, reps),
        time_closest(sets.reflected, at.closest_single, view, reps));
    rtcReleaseScene(scene);
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    Isa isa = best_isa();
    int reps = 5;
    RTCBuildQuality quality = RTC_BUILD_QUALITY_HIGH;
    std::vector<std::string> files;
    std::string only;  // --rays: comma-separated kinds, empty = all
    std::size_t spheres = 0;  // --spheres N: the sphere field instead of meshes
    bool shuffle = false;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--reps" && i + 1 < argc) {
            reps = std::max(1, std::atoi(argv[++i]));
        } else if (a == "--isa" && i + 1 < argc) {
            if (!parse_isa(argv[++i], isa)) return std::fprintf(stderr, "unknown level %s\n", argv[i]), 2;
        } else if (a == "--quality" && i + 1 < argc) {
            const std::string q = argv[++i];
            if (q != "medium" && q != "high") return std::fprintf(stderr, "--quality: medium or high\n"), 2;
            quality = q == "high" ? RTC_BUILD_QUALITY_HIGH : RTC_BUILD_QUALITY_MEDIUM;
        } else if (a == "--rays" && i + 1 < argc) {
            only = argv[++i];
        } else if (a == "--shuffle") {
            shuffle = true;
        } else if (a == "--spheres" && i + 1 < argc) {
            spheres = std::size_t(std::max(1.0, std::atof(argv[++i])));
        } else if (a == "-h" || a == "--help" || a.rfind("--", 0) == 0) {
            std::fprintf(stderr, "usage: embree_rays [--reps N] [--isa sse2|sse4.2|avx2|avx512] [--quality medium|high] "
                                 "[--rays primary,shadow,mirror,glass,diffuse] [--shuffle] MESH.{obj,ply} ... | --spheres N\n");
            return a == "-h" || a == "--help" ? 0 : 2;
        } else {
            files.push_back(a);
        }
    }
    if (files.empty() && spheres == 0) return std::fprintf(stderr, "usage: embree_rays [--reps N] [--isa LEVEL] [--quality medium|high] MESH.{obj,ply} ...\n"), 2;
    // Embree's advice for its kernels (denormals flushed); the same mode for streamrt's below.
    _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
    _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
    RTCDevice dev = rtcNewDevice("threads=1");
    if (!dev) return std::fprintf(stderr, "rtcNewDevice failed\n"), 1;
    rtcSetDeviceErrorFunction(dev, embree_error, nullptr);
    const KernelTable& kt = kernel_table(isa);
    std::printf("Embree %s (native 16-wide packets: %s), streamrt kernels %s (%d-lane packets); one thread, "
                "median of %d, Mrays/s\n",
                RTC_VERSION_STRING, rtcGetDeviceProperty(dev, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED) ? "yes" : "no",
                kt.name, kt.float_lanes, reps);
    if (spheres) {
        const int rc = sphere_field(dev, isa, spheres, reps, quality);
        rtcReleaseDevice(dev);
        return rc;
    }
    for (const std::string& file : files) {
        std::shared_ptr<const Mesh> mesh;
        const double t_read = now();
        try {
            mesh = load_mesh_file(file, false);
        } catch (const std::exception& e) {
            std::fprintf(stderr, "%s\n", e.what());
            return 1;
        }
        const double t_built = now();
        RTCScene scene = embree_scene(dev, *mesh, quality);
        const double t_embree = now() - t_built;
        ObjectXf xf{};
        xf.m[0] = xf.m[5] = xf.m[10] = 1.f;
        xf.mesh = &mesh->view();
        const View view = view_of_bounds(mesh->lo, mesh->hi);
        Streams s = make_streams(*mesh, kt, xf, view);
        if (shuffle)
            for (Stream* st : {&s.primary, &s.shadow, &s.mirror, &s.glass, &s.diffuse}) st->shuffle();
        std::printf("\n%s: %zu triangles; streamrt read + build %.2f s, Embree build (%s quality, 1 thread) "
                    "%.2f s; %dx%d view%s\n",
                    file.c_str(), mesh->triangle_count(), t_built - t_read,
                    quality == RTC_BUILD_QUALITY_HIGH ? "high" : "medium", t_embree, view.width, view.height,
                    shuffle ? ", rays in a random order" : "");
        std::printf("%-8s %9s %10s %10s %10s %7s %10s   %s\n", "rays", "count", "Embree16", "Embree1", "streamrt", "ratio",
                    "single", "hits: Embree16 / Embree1 / streamrt");
        const SingleRayMesh single(*mesh, xf);
        for (const RaySet& k : ray_sets(s, only)) {
            const Result e16 = embree16(scene, *k.st, k.any, reps);
            const Result e1 = embree1(scene, *k.st, k.any, reps);
            std::size_t hits = 0;
            const double ours = mrays(*k.st, k.any, kt, xf, reps, &hits);
            const double ours_single = mrays(*k.st, k.any, kt, single.xf, reps);
            std::printf("%-8s %9zu %10.2f %10.2f %10.2f %6.2fx %10.2f   %zu / %zu / %zu\n", k.name, k.st->count,
                        e16.mrays, e1.mrays, ours, ours / e16.mrays, ours_single, e16.hits, e1.hits, hits);
            std::fflush(stdout);
        }
        rtcReleaseScene(scene);
    }
    rtcReleaseDevice(dev);
    return 0;
}
