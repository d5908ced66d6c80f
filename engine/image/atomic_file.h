#pragma once
// Files written whole or not at all: through a temporary name in the target's folder,
// renamed into place once every byte is written. A failed or killed write leaves no file and
// no temporary (docs/robustness.md, "Output safety").
#include <sys/uio.h>

#include <atomic>
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <string_view>

namespace streamrt {

/// fill(fd) writes the content into the temporary; whatever stops it (an error, bad_alloc,
/// Ctrl-C: fill returns false) leaves no temporary behind and no file at `path`. `cancel` is
/// looked at once more after the last byte: a Ctrl-C during the final write still leaves no
/// file. Throws RenderError naming the path on failure; false when cancelled.
bool write_atomically(const std::string& path, const std::atomic<bool>* cancel, const std::function<bool(int)>& fill);

/// Writes every piece, a few hundred at a time (writev), resuming after short writes and
/// EINTR; std::system_error (errno) on failure.
void write_all(int fd, std::span<const iovec> pieces);

/// Allocates the blocks of bytes [offset, offset + bytes) of the open file before they are
/// written (Linux fallocate, the file's size unchanged; nothing where the file system cannot).
/// On ext4 a file renamed over an existing one has its delayed-allocation blocks allocated and
/// written out first, inside the rename (2.5 ms for a 2.7 MB PPM here); blocks allocated ahead
/// leave it nothing to do (docs/performance.md, "Image output").
void allocate_ahead(int fd, std::uint64_t offset, std::uint64_t bytes);

/// Writes `text` to `path` the way images are written: a temporary file in the same folder,
/// renamed into place once complete; on failure, no file and a RenderError naming the path.
void write_text_file(const std::string& path, std::string_view text);

}  // namespace streamrt
