#pragma once
// A file's bytes, mapped read-only where possible: the scene reader's files and the OBJ reader's
// meshes (no copy, and the pages are faulted in by whichever thread parses them).
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <string_view>
#include <system_error>

namespace streamrt {

/// A regular file's bytes: mapped read-only (the scene reader gives parsed ranges back, see
/// advise_inside), or read into a string when mapping is not possible (an empty-looking file
/// such as those of /proc).
class MappedFile {
  public:
    MappedFile() = default;
    MappedFile(const MappedFile&) = delete;
    MappedFile& operator=(const MappedFile&) = delete;
    ~MappedFile() {
        if (map_) ::munmap(map_, size_);
    }

    /// False when `p` is not a regular file or cannot be opened or read.
    bool open(const std::filesystem::path& p) {
        std::error_code ec;
        if (!std::filesystem::is_regular_file(p, ec)) return false;
        const int fd = ::open(p.c_str(), O_RDONLY | O_CLOEXEC);
        if (fd < 0) return false;
        struct stat st{};
        bool ok = ::fstat(fd, &st) == 0;
        if (ok && st.st_size > 0) {
            void* m = ::mmap(nullptr, std::size_t(st.st_size), PROT_READ, MAP_PRIVATE, fd, 0);
            if (m != MAP_FAILED) {
                map_ = m;
                size_ = std::size_t(st.st_size);
                ::madvise(map_, size_, MADV_SEQUENTIAL);
            }
        }
        if (ok && !map_) {
            char buf[1 << 16];
            for (ssize_t n; (n = ::read(fd, buf, sizeof buf)) != 0;) {
                if (n < 0) {
                    ok = false;
                    break;
                }
                owned_.append(buf, std::size_t(n));
            }
        }
        ::close(fd);
        return ok;
    }

    std::string_view text() const {
        return map_ ? std::string_view(static_cast<const char*>(map_), size_) : std::string_view(owned_);
    }
    bool mapped() const { return map_ != nullptr; }

  private:
    void* map_ = nullptr;
    std::size_t size_ = 0;
    std::string owned_;
};

}  // namespace streamrt
