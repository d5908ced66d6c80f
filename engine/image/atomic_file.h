#pragma once
// Files written whole or not at all: through a temporary name in the target's folder,
// renamed into place once every byte is written. A failed or killed write leaves no file and
// no temporary (docs/robustness.md, "Output safety").
#include <sys/uio.h>

#include <atomic>
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

/// Writes `text` to `path` the way images are written: a temporary file in the same folder,
/// renamed into place once complete; on failure, no file and a RenderError naming the path.
void write_text_file(const std::string& path, std::string_view text);

}  // namespace streamrt
