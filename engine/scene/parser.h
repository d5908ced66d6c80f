#pragma once
// Reads the line-oriented .cfg scene format (docs/scene-format.md). Every mistake throws a
// SceneError carrying file:line:col; a returned Scene is fully validated.
#include <cstddef>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "scene/scene.h"

namespace streamrt {

/// A file the reader read, and its bytes (ReadOptions::copies).
struct FileCopy {
    std::string path;  ///< as the reader named it (relative to the working folder or absolute)
    std::string bytes;
};

/// How a large text is read: cut into chunks at line ends, shapes of the chunks parsed in
/// parallel (docs/architecture.md, "Scene reading"). The Scene and the error are the same
/// for every setting.
struct ReadOptions {
    int jobs = 0;                          ///< threads; <= 0: all cores
    std::size_t chunk_bytes = 1u << 20;    ///< a chunk's size, extended to the next line end
    std::size_t chunked_from = 1u << 20;   ///< smaller texts are read in one sequential pass
    /// When set, receives a copy of every file read (the scene, its includes, its meshes), in
    /// reading order: what another machine needs to read the same scene (engine/distributed).
    std::vector<FileCopy>* copies = nullptr;
    /// Meshes a front end holds in memory (the Python module's Scene.mesh): a `mesh` statement
    /// names the K-th as `file=memory:K`. Null: no such name is accepted.
    const std::vector<std::shared_ptr<const Mesh>>* memory_meshes = nullptr;
};

/// Loads and validates a scene file, following `include` statements. `jobs` threads read a
/// large file (<= 0: all cores).
Scene load_scene(const std::string& path, int jobs = 0);
Scene load_scene(const std::string& path, const ReadOptions& options);

/// Parses scene text held in memory; `name` stands for the file in messages and is the base
/// for relative includes.
Scene parse_scene(std::string_view text, const std::string& name);
Scene parse_scene(std::string_view text, const std::string& name, const ReadOptions& options);

}  // namespace streamrt
