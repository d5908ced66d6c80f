#include "distributed/scene_bundle.h"

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "core/error.h"
#include "distributed/tile_file.h"

namespace streamrt {

namespace fs = std::filesystem;

namespace {

void put_string(std::string& out, std::string_view s) {
    const std::uint64_t n = s.size();
    out.append(reinterpret_cast<const char*>(&n), sizeof n);
    out.append(s);
}

std::string get_string(std::string_view& in) {
    std::uint64_t n = 0;
    if (in.size() < sizeof n) throw RenderError("scene bundle: truncated");
    std::memcpy(&n, in.data(), sizeof n);
    in.remove_prefix(sizeof n);
    if (in.size() < n) throw RenderError("scene bundle: truncated");
    std::string s(in.substr(0, n));
    in.remove_prefix(n);
    return s;
}

fs::path below(const fs::path& root, const std::string& path) {
    return root / fs::absolute(path).lexically_normal().relative_path();
}

}  // namespace

std::string SceneBundle::content_hash() const {
    std::uint64_t h = fnv1a("streamrt scene");
    for (const FileCopy& f : files) {
        const std::uint64_t n = f.bytes.size();
        h = fnv1a(std::string_view(reinterpret_cast<const char*>(&n), sizeof n), h);
        h = fnv1a(f.bytes, h);
    }
    return hex64(h);
}

std::string SceneBundle::serialize() const {
    std::string out;
    put_string(out, scene_path);
    put_string(out, std::to_string(files.size()));
    for (const FileCopy& f : files) {
        put_string(out, f.path);
        put_string(out, f.bytes);
    }
    return out;
}

SceneBundle SceneBundle::deserialize(std::string_view in) {
    SceneBundle b;
    b.scene_path = get_string(in);
    const std::size_t n = std::strtoull(get_string(in).c_str(), nullptr, 10);
    for (std::size_t i = 0; i < n; ++i) {
        FileCopy f;
        f.path = get_string(in);
        f.bytes = get_string(in);
        b.files.push_back(std::move(f));
    }
    return b;
}

Scene load_scene_bundled(const std::string& path, int jobs, SceneBundle& bundle) {
    ReadOptions options;
    options.jobs = jobs;
    options.copies = &bundle.files;
    bundle.scene_path = path;
    bundle.files.clear();
    return load_scene(path, options);
}

Scene load_scene_from_bundle(const SceneBundle& bundle, int jobs) {
    std::string templ = (fs::temp_directory_path() / "streamrt-scene-XXXXXX").string();
    if (!::mkdtemp(templ.data())) throw RenderError("cannot make a temporary folder for the scene: " + templ);
    const fs::path root = templ;
    struct Cleanup {
        fs::path root;
        ~Cleanup() {
            std::error_code ec;
            fs::remove_all(root, ec);
        }
    } cleanup{root};
    for (const FileCopy& f : bundle.files) {
        const fs::path target = below(root, f.path);
        fs::create_directories(target.parent_path());
        std::ofstream out(target, std::ios::binary);
        out.write(f.bytes.data(), std::streamsize(f.bytes.size()));
        if (!out) throw RenderError("cannot write the scene's copy " + target.string());
    }
    return load_scene(below(root, bundle.scene_path).string(), jobs);
}

}  // namespace streamrt
