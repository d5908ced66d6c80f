#include "mesh/mesh_bytes.h"

#include <sys/mman.h>
#include <zlib.h>

#include <algorithm>
#include <cctype>
#include <new>
#include <stdexcept>
#include <utility>

namespace streamrt {

namespace {

bool ends_with_gz(const std::string& path) {
    const std::size_t n = path.size();
    return n >= 3 && path[n - 3] == '.' && std::tolower(static_cast<unsigned char>(path[n - 2])) == 'g' &&
           std::tolower(static_cast<unsigned char>(path[n - 1])) == 'z';
}

}  // namespace

bool is_gzip_path(const std::string& path) { return ends_with_gz(path); }

std::string without_gzip_suffix(const std::string& path) {
    return ends_with_gz(path) ? path.substr(0, path.size() - 3) : path;
}

InflatedBytes& InflatedBytes::operator=(InflatedBytes&& o) noexcept {
    if (this != &o) {
        this->~InflatedBytes();
        data_ = std::exchange(o.data_, nullptr);
        size_ = std::exchange(o.size_, 0);
        capacity_ = std::exchange(o.capacity_, 0);
    }
    return *this;
}

InflatedBytes::~InflatedBytes() {
    if (data_) ::munmap(data_, capacity_);
    data_ = nullptr;
}

void InflatedBytes::reserve(std::size_t capacity) {
    if (capacity <= capacity_) return;
    void* p = data_ ? ::mremap(data_, capacity_, capacity, MREMAP_MAYMOVE)
                    : ::mmap(nullptr, capacity, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE,
                             -1, 0);
    if (p == MAP_FAILED) throw std::bad_alloc();
    data_ = static_cast<char*>(p);
    capacity_ = capacity;
}

InflatedBytes inflate_gzip(std::string_view in, MemoryBudget& budget) {
    z_stream z{};
    if (inflateInit2(&z, 16 + MAX_WBITS) != Z_OK) throw std::runtime_error("cannot start gzip decompression");
    struct End {
        z_stream& z;
        ~End() { inflateEnd(&z); }
    } end{z};
    // zlib counts in 32-bit uInt: input and output go in pieces of at most 1 GiB. Output is
    // counted against the budget a piece of at most kCounted bytes at a time, before zlib
    // writes it: past the budget by less than one piece, never by the whole text.
    constexpr std::size_t kPiece = std::size_t(1) << 30, kCounted = std::size_t(1) << 24;
    InflatedBytes out;
    std::size_t used = 0, counted = 0, fed = 0;
    const auto consumed = [&] { return fed - z.avail_in; };  // compressed bytes read so far
    const auto where = [&] { return " at byte " + std::to_string(consumed()) + " of the compressed file"; };
    const auto fail = [&](const std::string& what) { throw std::runtime_error(what + where()); };
    for (;;) {
        if (z.avail_in == 0 && fed < in.size()) {
            const std::size_t n = std::min(in.size() - fed, kPiece);
            z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(in.data() + fed));
            z.avail_in = uInt(n);
            fed += n;
        }
        if (used == counted) {
            const double piece = std::min(double(kCounted), budget.left());
            if (!(piece >= 1))
                throw MemoryShortage("gzip data inflates past " + budget.describe() + where() +
                                     "; --memory-limit raises it");
            budget.need(piece, "inflating");
            counted += std::size_t(piece);
            if (counted > out.capacity())
                out.reserve(std::max(counted, std::min(2 * out.capacity(), counted + kPiece)));
        }
        const std::size_t room = std::min(counted - used, kPiece);
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
    budget.release(double(counted - used));  // counted ahead, never written
    out.set_size(used);
    return out;
}

MeshBytes::MeshBytes(const std::string& path, MemoryBudget& budget) {
    file_.emplace();
    if (!file_->open(path)) throw std::runtime_error("cannot open mesh file");
    // The mapped text becomes resident as the reader goes through it: it counts.
    budget.need(double(file_->text().size()), "its text");
    if (is_gzip_path(path)) {
        inflated_ = inflate_gzip(file_->text(), budget);
        budget.release(double(file_->text().size()));
        file_.reset();  // the compressed bytes are no longer needed
    }
}

}  // namespace streamrt
