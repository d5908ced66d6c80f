#pragma once
// A scene file's bytes, mapped read-only where possible, and a path's identity for include
// cycles. Internal to the reader.
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <string_view>
#include <system_error>

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

/// A scene file's bytes: mapped read-only (the chunked reader gives parsed ranges back, see
/// advise_inside), or read into a string when mapping is not possible (an empty-looking file
/// such as those of /proc).
class FileText {
  public:
    FileText() = default;
    FileText(const FileText&) = delete;
    FileText& operator=(const FileText&) = delete;
    ~FileText() {
        if (map_) ::munmap(map_, size_);
    }

    bool open(const fs::path& p) {
        std::error_code ec;
        if (!fs::is_regular_file(p, ec)) return false;
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

}  // namespace streamrt::scene_reader
