#pragma once
// A mesh file's bytes for the OBJ and PLY readers: the file mapped as it is, or, for a
// gzip-compressed file (a path ending in `.gz`, any case: `dragon.ply.gz`, `room.obj.gz`, as
// scan repositories ship their models), inflated into memory first. The readers' errors then
// count lines and bytes in the inflated text, what `zcat FILE` shows.
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/default_init.h"
#include "core/mapped_file.h"

namespace streamrt {

/// Inflated bytes: not zero-filled before zlib writes them.
using InflatedBytes = std::vector<char, DefaultInitAllocator<char>>;

/// True when `path` ends in `.gz` (any case).
bool is_gzip_path(const std::string& path);

/// `path` without a trailing `.gz` (any case): the name whose extension says the format.
std::string without_gzip_suffix(const std::string& path);

class MeshBytes {
  public:
    /// Opens `path` (throws std::runtime_error "cannot open mesh file" when it cannot), and
    /// inflates it when is_gzip_path(path): std::runtime_error on corrupt or truncated data,
    /// with the compressed byte where it stopped, or when it would inflate to more than half
    /// this machine's memory.
    explicit MeshBytes(const std::string& path);
    std::string_view text() const {
        return file_ ? file_->text() : std::string_view(inflated_.data(), inflated_.size());
    }

  private:
    std::optional<MappedFile> file_;  ///< the file as it is (let go of once inflated)
    InflatedBytes inflated_;
};

/// Inflates gzip data (one member or several, concatenated as `cat a.gz b.gz` makes them)
/// into a string of at most `limit` bytes. Throws std::runtime_error naming the compressed
/// byte where it stopped.
InflatedBytes inflate_gzip(std::string_view compressed, std::size_t limit);

}  // namespace streamrt
