#pragma once
// A scene file's bytes (mapped, core/mapped_file.h) and a path's identity for include cycles.
// Internal to the reader.
#include <filesystem>
#include <system_error>

#include "core/mapped_file.h"

namespace streamrt::scene_reader {

namespace fs = std::filesystem;

/// A path's identity for cycle detection.
inline fs::path identity_of(const fs::path& p) {
    std::error_code ec;
    fs::path id = fs::weakly_canonical(p, ec);
    if (ec) {
        id = fs::absolute(p, ec);
        if (ec) id = p;
        id = id.lexically_normal();
    }
    return id;
}

/// A scene file's bytes (core/mapped_file.h).
using FileText = MappedFile;

}  // namespace streamrt::scene_reader
