#pragma once
// A scene as bytes: the scene file, its includes and its meshes, so that a process on
// another machine (no shared file system) reads exactly the same scene, and a content hash
// that binds shard parts and checkpoint journals to it.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "scene/parser.h"
#include "scene/scene.h"

namespace streamrt {

struct SceneBundle {
    std::string scene_path;       ///< the top-level file, as named on the command line
    std::vector<FileCopy> files;  ///< every file read, in reading order (scene first)

    /// FNV-1a over every file's name-free contents, in reading order: the scene's identity.
    std::string content_hash() const;
    std::string serialize() const;
    /// Throws RenderError on malformed bytes.
    static SceneBundle deserialize(std::string_view bytes);
};

/// Loads and validates the scene at `path` (SceneError as usual), keeping a copy of every
/// file read in `bundle`.
Scene load_scene_bundled(const std::string& path, int jobs, SceneBundle& bundle);

/// Reads the scene a bundle holds: its files are written under a private temporary folder
/// (each at its absolute path below it, so relative includes and meshes resolve), read, and
/// removed again.
Scene load_scene_from_bundle(const SceneBundle& bundle, int jobs);

}  // namespace streamrt
