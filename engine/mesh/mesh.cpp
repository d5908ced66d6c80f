#include "mesh/mesh.h"

#include <tiny_obj_loader.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <numbers>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "core/memory_budget.h"
#include "core/srgb.h"
#include "core/vec3.h"
#include "mesh/mesh_bytes.h"
#include "mesh/obj_reader.h"
#include "parallel/parallelism.h"

namespace streamrt {

std::size_t Mesh::memory_bytes() const {
    return positions.size() * sizeof(float) + blocks.size() * sizeof(TriangleBlock) +
           block_of.size() * sizeof(std::uint32_t) + index.size() * sizeof(std::uint32_t) +
           vertex_normals.size() * sizeof(float) + corner_uv.size() * sizeof(float) +
           vertex_colors.size() * sizeof(float) + bvh.memory_bytes();
}

double Mesh::build_bytes(std::size_t vertices, std::size_t triangles, bool uv, bool colors) {
    // Per vertex: its normal, its renumbering (4) and the kept positions when they are copied
    // (and its colour, copied too). Per triangle: the peak of Mesh::build above that, measured
    // (docs/performance.md, "Memory per vertex and triangle"): the kept vertex numbers (12),
    // the hierarchy builder's references (32) and nodes, then the finished arrays.
    constexpr double kPerVertex = 2 * 3 * sizeof(float) + sizeof(std::uint32_t);
    constexpr double kPerTriangle = 104, kPerTriangleUv = 4 + 24;
    return double(vertices) * (kPerVertex + (colors ? 2 * 3 * sizeof(float) : 0.0)) +
           double(triangles) * (kPerTriangle + (uv ? kPerTriangleUv : 0.0));
}

std::shared_ptr<const Mesh> Mesh::build_from(std::string name, const std::vector<float>& positions,
                                             std::vector<float>* own_positions,
                                             const std::vector<std::uint32_t>& triangles,
                                             std::vector<std::uint32_t>* own_triangles,
                                             const accel::BuildOptions& options,
                                             const std::vector<float>& corner_uv,
                                             const std::vector<float>& normals,
                                             const std::vector<float>& colors) {
    auto m = std::make_shared<Mesh>();
    m->name = std::move(name);
    const std::size_t input_verts = positions.size() / 3;
    const auto input_vertex = [&](std::uint32_t v) {
        return Vec3d{positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]};
    };
    // Keep the triangles with three distinct, valid vertices and a non-zero area (in double:
    // the cross product of float differences is nearly exact), written over the triangles' own
    // array when the caller gave it up (a kept triangle never lands after where it was read).
    const std::size_t input_tris = triangles.size() / 3;
    std::vector<std::uint32_t> kept;
    if (own_triangles) kept = std::move(*own_triangles);  // `triangles` is empty from here on
    else kept.assign(triangles.begin(), triangles.begin() + std::ptrdiff_t(3 * input_tris));
    std::vector<std::uint32_t> kept_from;  // the input triangle of each kept one (texture coordinates)
    std::size_t n_kept = 0;
    for (std::size_t k = 0; k < input_tris; ++k) {
        const std::uint32_t a = kept[3 * k], b = kept[3 * k + 1], c = kept[3 * k + 2];
        bool ok = a < input_verts && b < input_verts && c < input_verts && a != b && b != c && a != c;
        if (ok) {
            const Vec3d n = cross(input_vertex(b) - input_vertex(a), input_vertex(c) - input_vertex(a));
            ok = dot(n, n) > 0.0 && std::isfinite(dot(n, n));
        }
        if (ok) {
            kept[3 * n_kept] = a;
            kept[3 * n_kept + 1] = b;
            kept[3 * n_kept + 2] = c;
            ++n_kept;
            if (!corner_uv.empty()) kept_from.push_back(std::uint32_t(k));
        } else {
            ++m->dropped;
        }
    }
    kept.resize(3 * n_kept);
    const std::size_t n_tris = n_kept;

    // Keep the vertices the kept triangles use, renumbered in increasing order: a mesh read
    // with vertices it never uses (an OBJ group of a larger model) does not hold them.
    std::vector<float> given_normals;
    {
        constexpr std::uint32_t kUnused = ~std::uint32_t(0);
        std::vector<std::uint32_t> renumber(input_verts, kUnused);
        for (const std::uint32_t v : kept) renumber[v] = 0;
        std::uint32_t used = 0;
        for (std::uint32_t& r : renumber)
            if (r != kUnused) r = used++;
        const bool all_used = used == input_verts;
        const auto compact = [&](const std::vector<float>& per_vertex) {
            if (all_used) return per_vertex;
            std::vector<float> out;
            out.reserve(3 * std::size_t(used));
            for (std::size_t v = 0; v < input_verts; ++v)
                if (renumber[v] != kUnused) out.insert(out.end(), &per_vertex[3 * v], &per_vertex[3 * v + 3]);
            return out;
        };
        if (all_used && own_positions) m->positions = std::move(*own_positions);
        else m->positions = compact(positions);
        if (colors.size() == 3 * input_verts) m->vertex_colors = compact(colors);
        if (normals.size() == 3 * input_verts) given_normals = compact(normals);
        if (!all_used)
            for (std::uint32_t& v : kept) v = renumber[v];
    }
    // From here on, vertex numbers are the mesh's own.
    const std::size_t n_verts = m->positions.size() / 3;
    const std::vector<float>& kept_positions = m->positions;
    const auto vertex = [&](std::uint32_t v) {
        return Vec3d{kept_positions[3 * v], kept_positions[3 * v + 1], kept_positions[3 * v + 2]};
    };

    // Area-weighted vertex normals (the cross product's length is twice the area), summed in
    // the normals' own floats: no array of double sums (24 bytes a vertex) beside them. Each
    // face's normal is computed in double and rounded once; a vertex sums a handful of them
    // (6 on a closed mesh, on average), in file order, so the sum keeps float's precision.
    // Coordinates far from 1 (beyond 1e10 or below 1e-10) are scaled towards it first, so that
    // the products stay inside float's range: one factor for the whole mesh keeps the weights.
    double largest = 0.0;
    for (const float p : kept_positions) largest = std::max(largest, double(std::fabs(p)));
    const double scale = largest > 1e10 || (largest < 1e-10 && largest > 0.0) ? 1.0 / largest : 1.0;
    m->vertex_normals.assign(3 * n_verts, 0.f);
    for (std::size_t k = 0; k < n_tris; ++k) {
        const std::uint32_t* t = &kept[3 * k];
        const Vec3d n = cross((vertex(t[1]) - vertex(t[0])) * scale, (vertex(t[2]) - vertex(t[0])) * scale);
        for (int j = 0; j < 3; ++j) {
            float* acc = &m->vertex_normals[3 * std::size_t(t[j])];
            acc[0] += float(n.x);
            acc[1] += float(n.y);
            acc[2] += float(n.z);
        }
    }
    {
        const bool given = !given_normals.empty();
        for (std::size_t v = 0; v < n_verts; ++v) {
            float* out = &m->vertex_normals[3 * v];
            Vec3d n{out[0], out[1], out[2]};
            if (given) {
                const Vec3d g{given_normals[3 * v], given_normals[3 * v + 1], given_normals[3 * v + 2]};
                if (const double g_len = length(g); g_len > 0.0 && std::isfinite(g_len)) n = g;
            }
            const double len = length(n);
            n = len > 0.0 && std::isfinite(len) ? n * (1.0 / len) : Vec3d{0, 0, 1};
            out[0] = float(n.x);
            out[1] = float(n.y);
            out[2] = float(n.z);
        }
    }
    std::vector<float>().swap(given_normals);

    // The hierarchy over the triangles' boxes (padded outwards, accel::conservative_box),
    // made as the builder reads them: no array of boxes (24 bytes a triangle) to fill and free.
    m->bvh = accel::Bvh::build(
        n_tris,
        [&](std::size_t k) {
            double lo[3], hi[3];
            for (int a = 0; a < 3; ++a) {
                lo[a] = hi[a] = kept_positions[3 * kept[3 * k] + a];
                for (int j = 1; j < 3; ++j) {
                    const double p = kept_positions[3 * kept[3 * k + j] + a];
                    lo[a] = std::min(lo[a], p);
                    hi[a] = std::max(hi[a], p);
                }
            }
            return accel::conservative_box(lo, hi);
        },
        options);

    // Store the triangles' vertex numbers in leaf order, so leaves address them directly.
    m->index.resize(3 * n_tris);
    parallel_for_index(n_tris, 16384, [&](std::size_t k) {
        const std::uint32_t src = m->bvh.prim_index[k];
        for (int j = 0; j < 3; ++j) m->index[3 * k + j] = kept[3 * src + j];
    });
    std::vector<std::uint32_t>().swap(kept);  // in m->index now: freed before the blocks are made
    if (!corner_uv.empty()) {
        m->corner_uv.resize(6 * n_tris);
        double uv_length = 0.0, length_sum = 0.0;
        for (std::size_t k = 0; k < n_tris; ++k) {
            const std::uint32_t src = kept_from[m->bvh.prim_index[k]];
            std::copy_n(&corner_uv[6 * std::size_t(src)], 6, &m->corner_uv[6 * k]);
            for (int j = 0; j < 3; ++j) {
                const int i = (j + 1) % 3;
                const float* a = &m->corner_uv[6 * k];
                uv_length += std::hypot(double(a[2 * i]) - a[2 * j], double(a[2 * i + 1]) - a[2 * j + 1]);
                length_sum += length(vertex(m->index[3 * k + std::size_t(i)]) - vertex(m->index[3 * k + std::size_t(j)]));
            }
        }
        m->uv_density = length_sum > 0.0 && uv_length > 0.0 ? float(uv_length / length_sum) : 1.f;
    }
    m->bvh.prim_index.clear();
    m->bvh.prim_index.shrink_to_fit();
    for (int a = 0; a < 3; ++a) {
        m->lo[a] = n_tris ? std::numeric_limits<double>::infinity() : 0.0;
        m->hi[a] = n_tris ? -std::numeric_limits<double>::infinity() : 0.0;
    }
    for (std::size_t k = 0; k < kept_positions.size(); ++k) {  // every kept vertex is a corner
        const std::size_t a = k % 3;
        m->lo[a] = std::min(m->lo[a], double(kept_positions[k]));
        m->hi[a] = std::max(m->hi[a], double(kept_positions[k]));
    }
    m->build_triangle_blocks();
    m->set_view(kDefaultSingleRayLanes);
    return m;
}

namespace {

std::string read_file_bytes(const std::string& path, const char* what) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error(std::string("cannot open ") + what);
    std::ostringstream ss;
    ss << in.rdbuf();
    if (in.bad()) throw std::runtime_error(std::string("cannot read ") + what);
    return ss.str();
}

constexpr const char* kNeedsUv = "face without texture coordinates (vt), which a texture needs";

/// The texture coordinates of triangles[first, first + count) of `d` (6 per triangle).
void append_corner_uv(const ObjData& d, std::size_t first, std::size_t count, std::vector<float>& out) {
    for (std::size_t k = 3 * first; k < 3 * (first + count); ++k) {
        const std::uint32_t t = d.triangle_uv[k];  // every corner has one: parse_obj listed no gap
        out.push_back(d.texcoords[2 * std::size_t(t)]);
        out.push_back(d.texcoords[2 * std::size_t(t) + 1]);
    }
}

std::shared_ptr<const Mesh> build_checked(const std::string& path, std::vector<float>&& positions,
                                          std::vector<std::uint32_t>&& tris, const std::vector<float>& corner_uv,
                                          const std::vector<float>& colors, MemoryBudget& budget) {
    const std::size_t faces = tris.size() / 3;
    if (faces == 0) throw std::runtime_error("OBJ file has no faces");  // before anything is built
    budget.need(Mesh::build_bytes(positions.size() / 3, faces, !corner_uv.empty(), colors.size() == positions.size()),
                "building its " + std::to_string(faces) + " triangles");
    auto mesh = Mesh::build(path, std::move(positions), std::move(tris), {}, corner_uv, {}, colors);
    if (mesh->triangle_count() == 0)
        throw std::runtime_error("OBJ file has no triangles of non-zero area (" + std::to_string(faces) + " degenerate)");
    return mesh;
}

}  // namespace

std::shared_ptr<const Mesh> load_obj_mesh(const std::string& path, bool with_uv, bool with_colors) {
    MemoryBudget budget = MemoryBudget::now();  // read as this file's reading starts
    std::optional<MeshBytes> file(std::in_place, path, budget);  // mapped, or inflated from a .gz file
    ObjData d = parse_obj(file->text(), path, {.keep_uv = with_uv, .keep_colors = with_colors, .budget = &budget});
    std::vector<float> corner_uv;
    if (with_uv) {
        if (!d.uv_gaps.empty()) obj_fail_at(file->text(), path, d.uv_gaps.front().offset, kNeedsUv);
        budget.need(double(d.triangle_uv.size()) * 2 * sizeof(float), "its texture coordinates");
        corner_uv.reserve(2 * d.triangle_uv.size());
        append_corner_uv(d, 0, d.triangles.size() / 3, corner_uv);
    }
    if (with_colors) {
        if (d.colorless_offset != std::size_t(-1))
            obj_fail_at(file->text(), path, d.colorless_offset,
                        "vertex without a colour (v x y z r g b), which vertex_colors=true needs");
        // An OBJ file's colours are display values in [0, 1] (8-bit codes over 255, as the
        // tools that write them store them): decoded from sRGB to linear light, clamped first.
        for (float& c : d.colors) c = float(srgb_eotf(std::clamp(double(c), 0.0, 1.0)));
    }
    // Every message that quotes the text is said: it is given back before the mesh is built.
    budget.release(double(file->text().size()));
    file.reset();
    return build_checked(path, std::move(d.positions), std::move(d.triangles), corner_uv, d.colors, budget);
}

ObjModel load_obj_model(const std::string& path, bool with_uv) {
    MemoryBudget budget = MemoryBudget::now();  // read as this file's reading starts
    const MeshBytes file(path, budget);  // mapped, or inflated from a .gz file
    const ObjData d = parse_obj(file.text(), path, {.keep_uv = true, .budget = &budget});
    ObjModel model;
    // The library (tinyobjloader reads MTL files): the materials in file order, their numbers by name.
    std::map<std::string, int> ids;
    if (!d.mtllib.empty()) {
        const std::size_t slash = path.find_last_of('/');
        model.mtl_path = slash == std::string::npos ? d.mtllib : path.substr(0, slash + 1) + d.mtllib;
        std::istringstream mtl(read_file_bytes(model.mtl_path, ("material library '" + model.mtl_path + "'").c_str()));
        std::vector<tinyobj::material_t> materials;
        std::string warn, err;
        tinyobj::LoadMtl(&ids, &materials, &mtl, &warn, &err);
        for (const tinyobj::material_t& m : materials) {
            ObjMaterial o;
            o.name = m.name;
            for (int c = 0; c < 3; ++c) {
                o.kd[c] = m.diffuse[c];
                o.ks[c] = m.specular[c];
            }
            o.ns = m.shininess;
            o.ni = m.ior;
            o.d = m.dissolve;
            o.map_kd = m.diffuse_texname;
            model.materials.push_back(o);
        }
    }
    // The material of each usemtl line: none before the library is read or for a name it lacks.
    std::vector<int> use_material;
    for (const ObjData::MaterialUse& u : d.material_uses) {
        const auto it = u.before_library ? ids.end() : ids.find(u.name);
        use_material.push_back(it == ids.end() ? -1 : it->second);
    }
    const auto material_of = [&](std::size_t triangle) {  // the last usemtl at or before it
        const auto it = std::upper_bound(d.material_uses.begin(), d.material_uses.end(), triangle,
                                         [](std::size_t t, const ObjData::MaterialUse& u) { return t < u.first_triangle; });
        return it == d.material_uses.begin() ? -1 : use_material[std::size_t(it - d.material_uses.begin()) - 1];
    };
    const auto uv_for = [&](int m) {
        return with_uv || (m >= 0 && std::size_t(m) < model.materials.size() && !model.materials[std::size_t(m)].map_kd.empty());
    };
    for (const ObjData::UvGap& g : d.uv_gaps)  // in file order: the first gap that matters
        if (uv_for(material_of(g.triangle))) obj_fail_at(file.text(), path, g.offset, kNeedsUv);

    // One group per material (-1 first), each its triangles in file order: runs between usemtl lines.
    struct Group {
        std::vector<std::uint32_t> tris;
        std::vector<float> corner_uv;
    };
    std::map<int, Group> groups;
    const std::size_t n_tris = d.triangles.size() / 3;
    budget.need(double(n_tris) * (3 * sizeof(std::uint32_t) + 6 * sizeof(float)), "grouping its triangles by material");
    for (std::size_t u = 0, first = 0; first < n_tris; ++u) {
        const std::size_t end = u < d.material_uses.size() ? std::min(d.material_uses[u].first_triangle, n_tris) : n_tris;
        if (end > first) {
            const int key = u == 0 ? -1 : use_material[u - 1];
            Group& g = groups[key];
            g.tris.insert(g.tris.end(), d.triangles.begin() + std::ptrdiff_t(3 * first),
                          d.triangles.begin() + std::ptrdiff_t(3 * end));
            if (uv_for(key)) append_corner_uv(d, first, end - first, g.corner_uv);
        }
        first = std::max(first, end);
    }
    for (const auto& [key, g] : groups) {
        budget.need(Mesh::build_bytes(d.positions.size() / 3, g.tris.size() / 3, !g.corner_uv.empty(), false),
                    "building its " + std::to_string(g.tris.size() / 3) + " triangles of one material");
        auto mesh = Mesh::build(path, d.positions, g.tris, {}, g.corner_uv);
        if (mesh->triangle_count() == 0) continue;  // a group of degenerate faces only
        const int material = key >= 0 && std::size_t(key) < model.materials.size() ? key : -1;
        model.parts.push_back({std::move(mesh), material});
    }
    if (model.parts.empty())
        throw std::runtime_error(groups.empty() ? "OBJ file has no faces" : "OBJ file has no triangles of non-zero area");
    return model;
}

// ---- generated surfaces -------------------------------------------------------------------

namespace {
/// Makes every triangle counter-clockwise seen from outside a surface star-shaped about the
/// origin (its normal points away from the origin).
void orient_outwards(MeshData& m) {
    for (std::size_t k = 0; k + 2 < m.triangles.size(); k += 3) {
        const auto p = [&](int j) {
            const std::uint32_t v = m.triangles[k + std::size_t(j)];
            return Vec3d{m.positions[3 * v], m.positions[3 * v + 1], m.positions[3 * v + 2]};
        };
        const Vec3d n = cross(p(1) - p(0), p(2) - p(0));
        if (dot(n, p(0) + p(1) + p(2)) < 0.0) std::swap(m.triangles[k + 1], m.triangles[k + 2]);
    }
}
void push(MeshData& m, double x, double y, double z) {
    m.positions.push_back(float(x));
    m.positions.push_back(float(y));
    m.positions.push_back(float(z));
}
}  // namespace

MeshData uv_sphere(int rings, int segments) {
    MeshData m;
    const double pi = std::numbers::pi;
    push(m, 0, 1, 0);
    for (int i = 1; i < rings; ++i) {
        const double th = pi * i / rings;
        for (int j = 0; j < segments; ++j) {
            const double ph = 2 * pi * j / segments;
            push(m, std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph));
        }
    }
    push(m, 0, -1, 0);
    const std::uint32_t south = std::uint32_t(m.positions.size() / 3 - 1);
    const auto ring = [&](int i, int j) { return std::uint32_t(1 + (i - 1) * segments + (j % segments)); };
    for (int j = 0; j < segments; ++j) {
        m.triangles.insert(m.triangles.end(), {0u, ring(1, j), ring(1, j + 1)});
        m.triangles.insert(m.triangles.end(), {south, ring(rings - 1, j + 1), ring(rings - 1, j)});
    }
    for (int i = 1; i + 1 < rings; ++i)
        for (int j = 0; j < segments; ++j) {
            m.triangles.insert(m.triangles.end(), {ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)});
            m.triangles.insert(m.triangles.end(), {ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)});
        }
    orient_outwards(m);
    return m;
}

MeshData icosphere(int level) {
    const double g = (1 + std::sqrt(5.0)) / 2;
    std::vector<Vec3d> v = {{-1, g, 0}, {1, g, 0},  {-1, -g, 0}, {1, -g, 0}, {0, -1, g},  {0, 1, g},
                            {0, -1, -g}, {0, 1, -g}, {g, 0, -1},  {g, 0, 1},  {-g, 0, -1}, {-g, 0, 1}};
    for (Vec3d& p : v) p = normalize(p);
    std::vector<std::array<std::uint32_t, 3>> f = {
        {0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
        {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
        {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
    for (int l = 0; l < level; ++l) {
        std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> mid;
        const auto midpoint = [&](std::uint32_t a, std::uint32_t b) {
            const auto key = std::minmax(a, b);
            const auto it = mid.find(key);
            if (it != mid.end()) return it->second;
            v.push_back(normalize((v[a] + v[b]) * 0.5));
            const std::uint32_t id = std::uint32_t(v.size() - 1);
            mid.emplace(key, id);
            return id;
        };
        std::vector<std::array<std::uint32_t, 3>> next;
        next.reserve(f.size() * 4);
        for (const auto& t : f) {
            const std::uint32_t a = midpoint(t[0], t[1]), b = midpoint(t[1], t[2]), c = midpoint(t[2], t[0]);
            next.push_back({t[0], a, c});
            next.push_back({t[1], b, a});
            next.push_back({t[2], c, b});
            next.push_back({a, b, c});
        }
        f.swap(next);
    }
    MeshData m;
    for (const Vec3d& p : v) push(m, p.x, p.y, p.z);
    for (const auto& t : f) m.triangles.insert(m.triangles.end(), t.begin(), t.end());
    orient_outwards(m);
    return m;
}

MeshData cube_mesh(int n) {
    MeshData m;
    std::map<std::array<int, 3>, std::uint32_t> ids;
    const auto vertex = [&](std::array<int, 3> g) {
        const auto it = ids.find(g);
        if (it != ids.end()) return it->second;
        push(m, -1.0 + 2.0 * g[0] / n, -1.0 + 2.0 * g[1] / n, -1.0 + 2.0 * g[2] / n);
        const std::uint32_t id = std::uint32_t(m.positions.size() / 3 - 1);
        ids.emplace(g, id);
        return id;
    };
    for (int axis = 0; axis < 3; ++axis)
        for (int side : {0, n}) {
            const int ua = (axis + 1) % 3, va = (axis + 2) % 3;
            for (int i = 0; i < n; ++i)
                for (int j = 0; j < n; ++j) {
                    const auto at = [&](int di, int dj) {
                        std::array<int, 3> g{};
                        g[axis] = side;
                        g[ua] = i + di;
                        g[va] = j + dj;
                        return vertex(g);
                    };
                    m.triangles.insert(m.triangles.end(), {at(0, 0), at(1, 0), at(1, 1)});
                    m.triangles.insert(m.triangles.end(), {at(0, 0), at(1, 1), at(0, 1)});
                }
        }
    orient_outwards(m);
    return m;
}

bool write_obj(const std::string& path, const MeshData& m) {
    std::FILE* f = std::fopen(path.c_str(), "w");
    if (!f) return false;
    std::fprintf(f, "# generated by streamrt\n");
    for (std::size_t v = 0; v + 2 < m.positions.size(); v += 3)
        std::fprintf(f, "v %.9g %.9g %.9g\n", m.positions[v], m.positions[v + 1], m.positions[v + 2]);
    for (std::size_t k = 0; k + 2 < m.triangles.size(); k += 3)
        std::fprintf(f, "f %u %u %u\n", m.triangles[k] + 1, m.triangles[k + 1] + 1, m.triangles[k + 2] + 1);
    return std::fclose(f) == 0;
}

}  // namespace streamrt
