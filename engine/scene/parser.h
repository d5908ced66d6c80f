#pragma once
// Reads the line-oriented .cfg scene format (docs/scene-format.md). Every mistake throws a
// SceneError carrying file:line:col; a returned Scene is fully validated.
#include <string>
#include <string_view>

#include "scene/scene.h"

namespace streamrt {

/// Loads and validates a scene file, following `include` statements. `jobs` threads read a
/// large file (<= 0: all cores).
Scene load_scene(const std::string& path, int jobs = 0);

/// Parses scene text held in memory; `name` stands for the file in messages and is the base
/// for relative includes.
Scene parse_scene(std::string_view text, const std::string& name);

}  // namespace streamrt
