#include "mesh/mesh_bytes.h"

#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cctype>
#include <stdexcept>

namespace streamrt {

namespace {

bool ends_with_gz(const std::string& path) {
    const std::size_t n = path.size();
    return n >= 3 && path[n - 3] == '.' && std::tolower(static_cast<unsigned char>(path[n - 2])) == 'g' &&
           std::tolower(static_cast<unsigned char>(path[n - 1])) == 'z';
}

/// Half this machine's memory: more than that inflated is refused (a scan's text is a few GB
/// at most; a gzip bomb would otherwise end in the out-of-memory killer).
std::size_t default_limit() {
    const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGE_SIZE);
    return pages > 0 && page > 0 ? std::size_t(pages) * std::size_t(page) / 2 : std::size_t(1) << 32;
}

}  // namespace

bool is_gzip_path(const std::string& path) { return ends_with_gz(path); }

std::string without_gzip_suffix(const std::string& path) {
    return ends_with_gz(path) ? path.substr(0, path.size() - 3) : path;
}

InflatedBytes inflate_gzip(std::string_view in, std::size_t limit) {
    z_stream z{};
    if (inflateInit2(&z, 16 + MAX_WBITS) != Z_OK) throw std::runtime_error("cannot start gzip decompression");
    struct End {
        z_stream& z;
        ~End() { inflateEnd(&z); }
    } end{z};
    // zlib counts in 32-bit uInt: input and output go in pieces of at most 1 GiB.
    constexpr std::size_t kPiece = std::size_t(1) << 30;
    InflatedBytes out(std::min(limit, std::max<std::size_t>(4 * in.size(), std::size_t(1) << 16)));
    std::size_t used = 0, fed = 0;
    const auto consumed = [&] { return fed - z.avail_in; };  // compressed bytes read so far
    const auto fail = [&](const std::string& what) {
        throw std::runtime_error(what + " at byte " + std::to_string(consumed()) + " of the compressed file");
    };
    for (;;) {
        if (z.avail_in == 0 && fed < in.size()) {
            const std::size_t n = std::min(in.size() - fed, kPiece);
            z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(in.data() + fed));
            z.avail_in = uInt(n);
            fed += n;
        }
        if (used == out.size()) {
            if (out.size() >= limit)
                fail("gzip data inflates to more than " + std::to_string(limit) + " bytes (half this machine's memory)");
            out.resize(std::min(limit, 2 * out.size()));
        }
        const std::size_t room = std::min(out.size() - used, kPiece);
        z.next_out = reinterpret_cast<Bytef*>(out.data() + used);
        z.avail_out = uInt(room);
        const int rc = inflate(&z, Z_NO_FLUSH);
        used += room - z.avail_out;
        if (rc == Z_STREAM_END) {
            if (consumed() == in.size()) break;
            // Another member follows (gzip files may be concatenated); anything else is an error.
            const std::size_t at = consumed();
            if (in.size() - at < 2 || static_cast<unsigned char>(in[at]) != 0x1f ||
                static_cast<unsigned char>(in[at + 1]) != 0x8b)
                fail("data after the end of the gzip stream");
            inflateReset(&z);
            continue;
        }
        if (rc != Z_OK && rc != Z_BUF_ERROR) fail(std::string("corrupt gzip data (") + (z.msg ? z.msg : "zlib error") + ")");
        // No output room used up and nothing left to read: the stream stops before its end.
        if (z.avail_out != 0 && z.avail_in == 0 && fed == in.size()) fail("gzip data ends early (a truncated file?)");
    }
    out.resize(used);
    return out;
}

MeshBytes::MeshBytes(const std::string& path) {
    file_.emplace();
    if (!file_->open(path)) throw std::runtime_error("cannot open mesh file");
    if (is_gzip_path(path)) {
        inflated_ = inflate_gzip(file_->text(), default_limit());
        file_.reset();  // the compressed bytes are no longer needed
    }
}

}  // namespace streamrt
