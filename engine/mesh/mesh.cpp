#include "mesh/mesh.h"

#include <tiny_obj_loader.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include "core/vec3.h"
#include "parallel/parallelism.h"

namespace streamrt {

std::size_t Mesh::memory_bytes() const {
    return tri.size() * sizeof(float) + blocks.size() * sizeof(TriangleBlock) +
           block_of.size() * sizeof(std::uint32_t) + index.size() * sizeof(std::uint32_t) +
           vertex_normals.size() * sizeof(float) + corner_uv.size() * sizeof(float) + bvh.memory_bytes();
}

std::shared_ptr<const Mesh> Mesh::build(std::string name, const std::vector<float>& positions,
                                        const std::vector<std::uint32_t>& triangles,
                                        const accel::BuildOptions& options,
                                        const std::vector<float>& corner_uv,
                                        const std::vector<float>& normals) {
    auto m = std::make_shared<Mesh>();
    m->name = std::move(name);
    const std::size_t n_verts = positions.size() / 3;
    const auto vertex = [&](std::uint32_t v) {
        return Vec3d{positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]};
    };
    // Keep the triangles with three distinct, valid vertices and a non-zero area (in double:
    // the cross product of float differences is nearly exact).
    std::vector<std::uint32_t> kept;
    std::vector<std::uint32_t> kept_from;  // the input triangle of each kept one (texture coordinates)
    kept.reserve(triangles.size());
    for (std::size_t k = 0; k + 2 < triangles.size(); k += 3) {
        const std::uint32_t a = triangles[k], b = triangles[k + 1], c = triangles[k + 2];
        bool ok = a < n_verts && b < n_verts && c < n_verts && a != b && b != c && a != c;
        if (ok) {
            const Vec3d n = cross(vertex(b) - vertex(a), vertex(c) - vertex(a));
            ok = dot(n, n) > 0.0 && std::isfinite(dot(n, n));
        }
        if (ok) {
            kept.insert(kept.end(), {a, b, c});
            kept_from.push_back(std::uint32_t(k / 3));
        } else {
            ++m->dropped;
        }
    }
    const std::size_t n_tris = kept.size() / 3;

    // Area-weighted vertex normals (the cross product's length is twice the area).
    std::vector<double> acc(3 * n_verts, 0.0);
    for (std::size_t k = 0; k < n_tris; ++k) {
        const std::uint32_t* t = &kept[3 * k];
        const Vec3d n = cross(vertex(t[1]) - vertex(t[0]), vertex(t[2]) - vertex(t[0]));
        for (int j = 0; j < 3; ++j) {
            acc[3 * t[j]] += n.x;
            acc[3 * t[j] + 1] += n.y;
            acc[3 * t[j] + 2] += n.z;
        }
    }
    m->vertex_normals.resize(3 * n_verts);
    const bool given = normals.size() == 3 * n_verts;
    for (std::size_t v = 0; v < n_verts; ++v) {
        Vec3d n{acc[3 * v], acc[3 * v + 1], acc[3 * v + 2]};
        if (given) {
            const Vec3d g{normals[3 * v], normals[3 * v + 1], normals[3 * v + 2]};
            if (const double g_len = length(g); g_len > 0.0 && std::isfinite(g_len)) n = g;
        }
        const double len = length(n);
        n = len > 0.0 ? n * (1.0 / len) : Vec3d{0, 0, 1};
        m->vertex_normals[3 * v] = float(n.x);
        m->vertex_normals[3 * v + 1] = float(n.y);
        m->vertex_normals[3 * v + 2] = float(n.z);
    }

    // Triangle boxes (padded outwards, accel::conservative_box) and the hierarchy.
    std::vector<accel::Aabb> boxes(n_tris);
    parallel_for_index(n_tris, 16384, [&](std::size_t k) {
        double lo[3], hi[3];
        for (int a = 0; a < 3; ++a) {
            lo[a] = hi[a] = positions[3 * kept[3 * k] + a];
            for (int j = 1; j < 3; ++j) {
                const double p = positions[3 * kept[3 * k + j] + a];
                lo[a] = std::min(lo[a], p);
                hi[a] = std::max(hi[a], p);
            }
        }
        boxes[k] = accel::conservative_box(lo, hi);
    });
    m->bvh = accel::Bvh::build(std::move(boxes), options);

    // Store the triangles in leaf order, so leaves address them directly.
    m->tri.resize(9 * n_tris);
    m->index.resize(3 * n_tris);
    parallel_for_index(n_tris, 16384, [&](std::size_t k) {
        const std::uint32_t src = m->bvh.prim_index[k];
        for (int j = 0; j < 3; ++j) {
            const std::uint32_t v = kept[3 * src + j];
            m->index[3 * k + j] = v;
            for (int a = 0; a < 3; ++a) m->tri[9 * k + 3 * j + a] = positions[3 * v + a];
        }
    });
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
    for (std::size_t k = 0; k < 3 * n_tris; ++k)
        for (int a = 0; a < 3; ++a) {
            m->lo[a] = std::min(m->lo[a], double(m->tri[3 * k + a]));
            m->hi[a] = std::max(m->hi[a], double(m->tri[3 * k + a]));
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

/// The triangles of an OBJ text, grouped by material id (all in group -1 unless by_material),
/// with their corners' texture coordinates where uv_for(group) says so.
struct ObjFaces {
    std::vector<float> positions;
    struct Group {
        std::vector<std::uint32_t> tris;
        std::vector<float> corner_uv;
    };
    std::map<int, Group> groups;
    std::vector<tinyobj::material_t> materials;
};

template <class UvFor>
ObjFaces read_obj_faces(const std::string& obj_text, const std::string& mtl_text, bool by_material, UvFor uv_for) {
    tinyobj::ObjReaderConfig config;
    config.triangulate = true;
    config.vertex_color = false;
    tinyobj::ObjReader reader;
    // From strings: the material text is the one given (none: `mtllib` lines are ignored).
    if (!reader.ParseFromString(obj_text, mtl_text, config)) {
        std::string err = reader.Error();
        while (!err.empty() && (err.back() == '\n' || err.back() == '\r')) err.pop_back();
        throw std::runtime_error("cannot parse OBJ file: " + err);
    }
    ObjFaces out;
    const tinyobj::attrib_t& at = reader.GetAttrib();
    out.positions.assign(at.vertices.begin(), at.vertices.end());
    out.materials = reader.GetMaterials();
    // The group of the previous face, looked up again only when the material changes.
    int last_key = -2;
    ObjFaces::Group* group = nullptr;
    bool with_uv = false;
    for (const tinyobj::shape_t& s : reader.GetShapes()) {
        std::size_t off = 0;
        for (std::size_t f = 0; f < s.mesh.num_face_vertices.size(); ++f) {
            const auto nv = s.mesh.num_face_vertices[f];
            const int key = by_material && f < s.mesh.material_ids.size() ? s.mesh.material_ids[f] : -1;
            if (nv == 3) {
                if (key != last_key) {
                    group = &out.groups[key];
                    with_uv = uv_for(key);
                    last_key = key;
                }
                ObjFaces::Group& g = *group;
                for (int j = 0; j < 3; ++j) {
                    const tinyobj::index_t& ix = s.mesh.indices[off + std::size_t(j)];
                    const int v = ix.vertex_index;
                    if (v < 0 || std::size_t(v) >= out.positions.size() / 3)
                        throw std::runtime_error("OBJ face refers to a missing vertex");
                    g.tris.push_back(std::uint32_t(v));
                    if (!with_uv) continue;
                    const int t = ix.texcoord_index;
                    if (t < 0 || 2 * std::size_t(t) + 1 >= at.texcoords.size())
                        throw std::runtime_error("OBJ file has a face without texture coordinates (vt), which a "
                                                 "texture needs");
                    g.corner_uv.push_back(at.texcoords[2 * std::size_t(t)]);
                    g.corner_uv.push_back(at.texcoords[2 * std::size_t(t) + 1]);
                }
            }
            off += nv;
        }
    }
    for (float p : out.positions)
        if (!std::isfinite(p)) throw std::runtime_error("OBJ file has a vertex that is not finite");
    for (const auto& [key, g] : out.groups)
        for (float t : g.corner_uv)
            if (!std::isfinite(t)) throw std::runtime_error("OBJ file has a texture coordinate that is not finite");
    return out;
}

std::shared_ptr<const Mesh> build_checked(const std::string& path, const std::vector<float>& positions,
                                          const ObjFaces::Group& g) {
    const std::size_t faces = g.tris.size() / 3;
    auto mesh = Mesh::build(path, positions, g.tris, {}, g.corner_uv);
    if (mesh->triangle_count() == 0)
        throw std::runtime_error(faces == 0 ? "OBJ file has no faces"
                                            : "OBJ file has no triangles of non-zero area (" +
                                                  std::to_string(faces) + " degenerate)");
    return mesh;
}

}  // namespace

std::shared_ptr<const Mesh> load_obj_mesh(const std::string& path, bool with_uv) {
    const ObjFaces faces = read_obj_faces(read_file_bytes(path, "mesh file"), "", false, [&](int) { return with_uv; });
    static const ObjFaces::Group kNone;
    const auto it = faces.groups.find(-1);
    return build_checked(path, faces.positions, it == faces.groups.end() ? kNone : it->second);
}

ObjModel load_obj_model(const std::string& path, bool with_uv) {
    const std::string obj_text = read_file_bytes(path, "mesh file");
    ObjModel model;
    std::string mtl_text;
    {
        std::istringstream lines(obj_text);
        std::string line;
        while (std::getline(lines, line)) {
            std::istringstream words(line);
            std::string word, name;
            if (words >> word && word == "mtllib" && words >> name) {
                const std::size_t slash = path.find_last_of('/');
                model.mtl_path = slash == std::string::npos ? name : path.substr(0, slash + 1) + name;
                mtl_text = read_file_bytes(model.mtl_path, ("material library '" + model.mtl_path + "'").c_str());
                break;
            }
        }
    }
    std::vector<bool> mapped;  // per material: has map_Kd
    const auto uv_for = [&](int m) { return with_uv || (m >= 0 && std::size_t(m) < mapped.size() && mapped[m]); };
    // The materials are known only once parsed: a first pass without coordinates finds them.
    {
        tinyobj::ObjReaderConfig config;
        tinyobj::ObjReader reader;
        if (reader.ParseFromString("mtllib library\n", mtl_text, config))
            for (const tinyobj::material_t& m : reader.GetMaterials()) mapped.push_back(!m.diffuse_texname.empty());
    }
    const ObjFaces faces = read_obj_faces(obj_text, mtl_text, true, uv_for);
    for (const tinyobj::material_t& m : faces.materials) {
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
    for (const auto& [key, g] : faces.groups) {
        auto mesh = Mesh::build(path, faces.positions, g.tris, {}, g.corner_uv);
        if (mesh->triangle_count() == 0) continue;  // a group of degenerate faces only
        const int material = key >= 0 && std::size_t(key) < model.materials.size() ? key : -1;
        model.parts.push_back({std::move(mesh), material});
    }
    if (model.parts.empty())
        throw std::runtime_error(faces.groups.empty() ? "OBJ file has no faces"
                                                      : "OBJ file has no triangles of non-zero area");
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
