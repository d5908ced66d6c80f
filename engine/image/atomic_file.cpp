#include "image/atomic_file.h"

#include <fcntl.h>
#include <limits.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <system_error>
#include <vector>

#include "core/error.h"

namespace streamrt {

namespace fs = std::filesystem;

bool write_atomically(const std::string& path, const std::atomic<bool>* cancel, const std::function<bool(int)>& fill) {
    const fs::path target(path);
    std::string tmp_name = ".";  // appended, not "." + ...: GCC 12 warns falsely on that
    tmp_name += target.filename().string() + ".tmp" + std::to_string(::getpid());
    const fs::path tmp = target.parent_path() / tmp_name;
    const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (fd < 0) throw RenderError(path + ": cannot write: " + std::strerror(errno));
    bool written = false;
    try {
        written = fill(fd);
    } catch (const std::system_error& e) {
        ::close(fd);
        ::unlink(tmp.c_str());
        throw RenderError(path + ": write failed: " + std::strerror(e.code().value()));
    } catch (...) {
        ::close(fd);
        ::unlink(tmp.c_str());
        throw;
    }
    if (::close(fd) != 0 && written) {
        const int err = errno;
        ::unlink(tmp.c_str());
        throw RenderError(path + ": write failed: " + std::strerror(err));
    }
    if (!written || (cancel && cancel->load())) {
        ::unlink(tmp.c_str());
        return false;
    }
    if (std::rename(tmp.c_str(), target.c_str()) != 0) {
        const int err = errno;
        ::unlink(tmp.c_str());
        throw RenderError(path + ": cannot rename into place: " + std::strerror(err));
    }
    return true;
}

void allocate_ahead(int fd, std::uint64_t offset, std::uint64_t bytes) {
    if (bytes == 0) return;
    // An error (EOPNOTSUPP on file systems without it, ENOSPC) is left to the write that follows.
    (void)::fallocate(fd, FALLOC_FL_KEEP_SIZE, off_t(offset), off_t(bytes));
}

void write_all(int fd, std::span<const iovec> pieces) {
    std::vector<iovec> rest(pieces.begin(), pieces.end());
    std::size_t i = 0;
    while (i < rest.size()) {
        if (rest[i].iov_len == 0) {
            ++i;
            continue;
        }
        const ssize_t n = ::writev(fd, &rest[i], int(std::min<std::size_t>(rest.size() - i, IOV_MAX)));
        if (n < 0) {
            if (errno == EINTR) continue;
            throw std::system_error(errno, std::generic_category());
        }
        for (std::size_t left = std::size_t(n); left > 0;) {
            const std::size_t take = std::min(left, rest[i].iov_len);
            rest[i].iov_base = static_cast<char*>(rest[i].iov_base) + take;
            rest[i].iov_len -= take;
            left -= take;
            if (rest[i].iov_len == 0) ++i;
        }
    }
}


void write_text_file(const std::string& path, std::string_view text) {
    write_atomically(path, nullptr, [&](int fd) {
        const iovec piece{const_cast<char*>(text.data()), text.size()};
        write_all(fd, std::span<const iovec>(&piece, 1));
        return true;
    });
}

}  // namespace streamrt
