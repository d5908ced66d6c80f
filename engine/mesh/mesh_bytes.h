#pragma once
// A mesh file's bytes for the OBJ and PLY readers: the file mapped as it is, or, for a
// gzip-compressed file (a path ending in `.gz`, any case: `dragon.ply.gz`, `room.obj.gz`, as
// scan repositories ship their models), inflated into memory first. The readers' errors then
// count lines and bytes in the inflated text, what `zcat FILE` shows. Both count against the
// reading's memory budget (core/memory_budget.h): a gzip file stops inflating as soon as its
// text would not fit, at the compressed byte where it got to.
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

#include "core/mapped_file.h"
#include "core/memory_budget.h"

namespace streamrt {

/// True when `path` ends in `.gz` (any case).
bool is_gzip_path(const std::string& path);

/// `path` without a trailing `.gz` (any case): the name whose extension says the format.
std::string without_gzip_suffix(const std::string& path);

/// Inflated bytes in anonymous memory that grows in place (mremap): growing copies nothing
/// and holds no page beyond those written, so inflating N bytes holds N bytes at its peak
/// (a vector doubles: 1.5 N while it copies, and the copies take time).
class InflatedBytes {
  public:
    InflatedBytes() = default;
    InflatedBytes(InflatedBytes&& o) noexcept { *this = std::move(o); }
    InflatedBytes& operator=(InflatedBytes&& o) noexcept;
    InflatedBytes(const InflatedBytes&) = delete;
    InflatedBytes& operator=(const InflatedBytes&) = delete;
    ~InflatedBytes();
    char* data() { return data_; }
    const char* data() const { return data_; }
    std::size_t size() const { return size_; }
    std::size_t capacity() const { return capacity_; }
    /// Room for `capacity` bytes (never less than size()); throws std::bad_alloc.
    void reserve(std::size_t capacity);
    void set_size(std::size_t n) { size_ = n; }

  private:
    char* data_ = nullptr;
    std::size_t size_ = 0, capacity_ = 0;
};

class MeshBytes {
  public:
    /// Opens `path` (throws std::runtime_error "cannot open mesh file" when it cannot) and
    /// counts its text against `budget` (MemoryShortage when it does not fit); inflates it
    /// when is_gzip_path(path): std::runtime_error on corrupt or truncated data, with the
    /// compressed byte where it stopped, MemoryShortage when it inflates past the budget.
    MeshBytes(const std::string& path, MemoryBudget& budget);
    std::string_view text() const {
        return file_ ? file_->text() : std::string_view(inflated_.data(), inflated_.size());
    }

  private:
    std::optional<MappedFile> file_;  ///< the file as it is (let go of once inflated)
    InflatedBytes inflated_;
};

/// Inflates gzip data (one member or several, concatenated as `cat a.gz b.gz` makes them),
/// counting each piece against `budget` as it is written. Throws std::runtime_error naming
/// the compressed byte where it stopped, MemoryShortage ("gzip data inflates past the memory
/// budget (...) at byte N of the compressed file; ...") when it does not fit.
InflatedBytes inflate_gzip(std::string_view compressed, MemoryBudget& budget);
/// The same within at most `limit` bytes (tests, fuzzing).
inline InflatedBytes inflate_gzip(std::string_view compressed, std::size_t limit) {
    MemoryBudget budget = MemoryBudget::of(double(limit));
    return inflate_gzip(compressed, budget);
}

}  // namespace streamrt
