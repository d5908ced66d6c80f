#include "distributed/tile_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>

#include "core/error.h"
#include "parallel/parallelism.h"

namespace streamrt {

namespace {

constexpr std::uint32_t kRecordMagic = 0x454c4954u;  // "TILE" little-endian
constexpr const char* kMagic = "streamrt-tiles 2";  // 2: records count diffuse rays

// Fixed part of a record: magic, index, 4 ray counts, seconds; then pixels; then checksum.
constexpr std::size_t kRecordHead = 4 + 4 + 5 * 8 + 8;

template <class T>
void put(std::string& out, const T& v) {
    out.append(reinterpret_cast<const char*>(&v), sizeof v);
}
template <class T>
T get(const char* p) {
    T v;
    std::memcpy(&v, p, sizeof v);
    return v;
}

double now_seconds() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::string errno_text() { return std::strerror(errno); }

bool parse_int(std::string_view s, int& out) {
    const auto r = std::from_chars(s.data(), s.data() + s.size(), out);
    return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

}  // namespace

std::uint64_t fnv1a(std::string_view bytes, std::uint64_t h) {
    for (const char c : bytes) {
        h ^= static_cast<unsigned char>(c);
        h *= 1099511628211ull;
    }
    return h;
}

std::string hex64(std::uint64_t v) {
    char buf[17];
    std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(v));
    return buf;
}

std::string TileFileHeader::line() const {
    std::string set = shards > 0 ? std::to_string(shard) + "/" + std::to_string(shards) : "all";
    return std::string(kMagic) + " scene=" + scene + " settings=" + settings + " size=" + std::to_string(width) + "x" +
           std::to_string(height) + " tiles=" + std::to_string(tiles) + " set=" + set;
}

std::optional<TileFileHeader> TileFileHeader::parse(std::string_view line) {
    if (line.substr(0, std::strlen(kMagic)) != kMagic) return std::nullopt;
    line.remove_prefix(std::strlen(kMagic));
    TileFileHeader h;
    bool has_scene = false, has_settings = false, has_size = false, has_tiles = false, has_set = false;
    while (!line.empty()) {
        if (line.front() != ' ') return std::nullopt;
        line.remove_prefix(1);
        const std::size_t end = std::min(line.find(' '), line.size());
        const std::string_view word = line.substr(0, end);
        line.remove_prefix(end);
        const std::size_t eq = word.find('=');
        if (eq == std::string_view::npos) return std::nullopt;
        const std::string_view key = word.substr(0, eq), value = word.substr(eq + 1);
        if (key == "scene") h.scene = std::string(value), has_scene = true;
        else if (key == "settings") h.settings = std::string(value), has_settings = true;
        else if (key == "size") {
            const std::size_t x = value.find('x');
            has_size = x != std::string_view::npos && parse_int(value.substr(0, x), h.width) &&
                       parse_int(value.substr(x + 1), h.height) && h.width > 0 && h.height > 0;
        } else if (key == "tiles") has_tiles = parse_int(value, h.tiles) && h.tiles > 0;
        else if (key == "set") {
            if (value == "all") has_set = true;
            else {
                const std::size_t slash = value.find('/');
                has_set = slash != std::string_view::npos && parse_int(value.substr(0, slash), h.shard) &&
                          parse_int(value.substr(slash + 1), h.shards) && h.shard >= 0 && h.shard < h.shards;
            }
        } else return std::nullopt;
    }
    if (!has_scene || !has_settings || !has_size || !has_tiles || !has_set) return std::nullopt;
    if (h.tiles != tile_count(h.width, h.height)) return std::nullopt;
    return h;
}

std::string TileFileHeader::setting(std::string_view key) const {
    std::string_view rest = settings;
    while (!rest.empty()) {
        const std::size_t end = std::min(rest.find(','), rest.size());
        const std::string_view item = rest.substr(0, end);
        if (item.size() > key.size() && item.substr(0, key.size()) == key && item[key.size()] == '=')
            return std::string(item.substr(key.size() + 1));
        rest.remove_prefix(std::min(rest.size(), end + 1));
    }
    return "";
}

void apply_display_settings(const TileFileHeader& h, RenderSettings& s) {
    // The names of the settings token (driver/render_job.h, settings_token).
    s.calibration = value_named(kCalibrationNames, h.setting("calibration")).value_or(Calibration::Clamp);
    s.colorspace = value_named(kColorSpaceNames, h.setting("colorspace")).value_or(ColorSpace::Srgb);
    s.tonemap = value_named(kTonemapNames, h.setting("tonemap")).value_or(Tonemap::Clamp);
    const std::string e = h.setting("exposure");
    const double exposure = e.empty() ? 1.0 : std::strtod(e.c_str(), nullptr);
    s.exposure = exposure > 0 ? exposure : 1.0;
    s.exr = value_named(kExrPixelsNames, h.setting("exr")).value_or(ExrPixels::Half);
}

void append_tile_record(std::string& out, const TileOutput& t) {
    const std::size_t begin = out.size();
    put(out, kRecordMagic);
    put(out, std::int32_t(t.index));
    put(out, t.counts.primary);
    put(out, t.counts.shadow);
    put(out, t.counts.reflected);
    put(out, t.counts.refracted);
    put(out, t.counts.diffuse);
    put(out, t.seconds);
    out.append(reinterpret_cast<const char*>(t.rgb), std::size_t(t.tile.width() * t.tile.height()) * 3 * sizeof(float));
    put(out, fnv1a(std::string_view(out).substr(begin)));
}

std::size_t read_tile_records(std::string_view data, int width, int height, const TileSink& sink) {
    const int tiles = tile_count(width, height);
    std::size_t pos = 0;
    std::vector<float> rgb;
    while (data.size() - pos >= kRecordHead) {
        const char* p = data.data() + pos;
        if (get<std::uint32_t>(p) != kRecordMagic) break;
        TileOutput t;
        t.index = get<std::int32_t>(p + 4);
        if (t.index < 0 || t.index >= tiles) break;
        t.tile = tile_rect(width, height, t.index);
        t.counts = RayCounts{get<std::uint64_t>(p + 8), get<std::uint64_t>(p + 16), get<std::uint64_t>(p + 24),
                             get<std::uint64_t>(p + 32), get<std::uint64_t>(p + 40)};
        t.seconds = get<double>(p + 48);
        const std::size_t pixel_bytes = std::size_t(t.tile.width() * t.tile.height()) * 3 * sizeof(float);
        const std::size_t size = kRecordHead + pixel_bytes + 8;
        if (data.size() - pos < size) break;
        if (fnv1a(data.substr(pos, size - 8)) != get<std::uint64_t>(p + size - 8)) break;
        rgb.resize(pixel_bytes / sizeof(float));
        std::memcpy(rgb.data(), p + kRecordHead, pixel_bytes);
        t.rgb = rgb.data();
        sink(t);
        pos += size;
    }
    return pos;
}

std::vector<int> shard_tiles(int tiles, int k, int n) {
    std::vector<int> out;
    for (int i = k; i < tiles; i += n) out.push_back(i);
    return out;
}

void parse_shard(const std::string& text, int& k, int& n) {
    const std::size_t slash = text.find('/');
    const std::string_view s(text);
    if (slash == std::string::npos || !parse_int(s.substr(0, slash), k) || !parse_int(s.substr(slash + 1), n))
        throw UsageError("--shard " + text + ": expected K/N, the K-th (from 0) of N tile sets");
    if (n < 1 || k < 0 || k >= n)
        throw UsageError("--shard " + text + ": K/N needs N >= 1 and 0 <= K < N");
}

TileAssembly::TileAssembly(int width, int height)
    : image_(Framebuffer::uninitialized(width, height)),
      placed_(std::size_t(tile_count(width, height)), 0),
      costs_(placed_.size()) {}

bool TileAssembly::place(const TileOutput& t) {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        if (placed_[std::size_t(t.index)]) return false;
        placed_[std::size_t(t.index)] = 1;
        costs_[std::size_t(t.index)] = Cost{t.counts, t.seconds};
    }
    for (int y = t.tile.y0; y < t.tile.y1; ++y)
        std::memcpy(image_.pixel(t.tile.x0, y), t.rgb + std::size_t((y - t.tile.y0) * t.tile.width()) * 3,
                    std::size_t(t.tile.width()) * 3 * sizeof(float));
    return true;
}

int TileAssembly::missing() const {
    std::lock_guard<std::mutex> lock(mutex_);
    int n = 0;
    for (const unsigned char p : placed_) n += p ? 0 : 1;
    return n;
}

RayCounts TileAssembly::counts() const {
    std::lock_guard<std::mutex> lock(mutex_);
    RayCounts c;
    for (const Cost& cost : costs_) c += cost.counts;
    return c;
}

std::string TileAssembly::records(std::span<const int> tiles) const {
    std::string out;
    std::vector<float> rgb(std::size_t(kTileSize * kTileSize * 3));
    for (const int i : tiles) {
        TileOutput t;
        t.index = i;
        t.tile = tile_rect(image_.width, image_.height, i);
        t.counts = costs_[std::size_t(i)].counts;
        t.seconds = costs_[std::size_t(i)].seconds;
        for (int y = t.tile.y0; y < t.tile.y1; ++y)
            std::memcpy(&rgb[std::size_t((y - t.tile.y0) * t.tile.width()) * 3], image_.pixel(t.tile.x0, y),
                        std::size_t(t.tile.width()) * 3 * sizeof(float));
        t.rgb = rgb.data();
        append_tile_record(out, t);
    }
    return out;
}

std::string TileAssembly::costs_csv() const {
    std::lock_guard<std::mutex> lock(mutex_);
    std::string out = "index,x0,y0,x1,y1,rays,seconds\n";
    char line[160];
    for (int i = 0; i < int(placed_.size()); ++i) {
        if (!placed_[std::size_t(i)]) continue;
        const Tile t = tile_rect(image_.width, image_.height, i);
        std::snprintf(line, sizeof line, "%d,%d,%d,%d,%d,%llu,%.6f\n", i, t.x0, t.y0, t.x1, t.y1,
                      static_cast<unsigned long long>(costs_[std::size_t(i)].counts.total()),
                      costs_[std::size_t(i)].seconds);
        out += line;
    }
    return out;
}

// ---- journal ------------------------------------------------------------------------------

namespace {

bool read_whole(const std::string& path, std::string& out) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return false;
    out.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    return !in.bad();
}

void write_all(int fd, std::string_view bytes, const std::string& path) {
    while (!bytes.empty()) {
        const ssize_t n = ::write(fd, bytes.data(), bytes.size());
        if (n < 0) {
            if (errno == EINTR) continue;
            throw RenderError(path + ": cannot write the journal: " + errno_text());
        }
        bytes.remove_prefix(std::size_t(n));
    }
}

}  // namespace

TileJournal::TileJournal(const std::string& path, const TileFileHeader& header, bool resume, TileAssembly& assembly,
                         double sync_seconds)
    : path_(path), sync_seconds_(sync_seconds) {
    std::string old;
    const bool exists = ::access(path.c_str(), F_OK) == 0;
    if (exists && !resume)
        throw UsageError("checkpoint " + path + " exists: continue it with --resume, or remove it");
    if (exists) {
        if (!read_whole(path, old)) throw UsageError("checkpoint " + path + ": cannot read it: " + errno_text());
        const std::size_t nl = old.find('\n');
        const auto h = TileFileHeader::parse(std::string_view(old).substr(0, nl == std::string::npos ? 0 : nl));
        if (!h) throw UsageError("checkpoint " + path + ": not a streamrt journal");
        if (h->scene != header.scene)
            throw UsageError("checkpoint " + path + " belongs to another scene (content " + h->scene + ", this one " +
                             header.scene + ")");
        if (h->settings != header.settings || h->tiles != header.tiles || h->shards != header.shards ||
            h->shard != header.shard)
            throw UsageError("checkpoint " + path + " was made with other settings (" + h->settings + " " +
                             h->line().substr(h->line().rfind(' ') + 1) + "; now " + header.settings + " " +
                             header.line().substr(header.line().rfind(' ') + 1) + ")");
        const std::string_view records = std::string_view(old).substr(nl + 1);
        const std::size_t valid = read_tile_records(records, assembly.image().width, assembly.image().height,
                                                    [&](const TileOutput& t) { resumed_ += assembly.place(t) ? 1 : 0; });
        fd_ = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
        // A torn last record (the process died while appending) is cut off.
        if (fd_ < 0 || ::ftruncate(fd_, off_t(nl + 1 + valid)) != 0 || ::lseek(fd_, 0, SEEK_END) < 0)
            throw RenderError(path + ": cannot continue the journal: " + errno_text());
    } else {
        fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
        if (fd_ < 0) throw UsageError("checkpoint " + path + ": cannot create it: " + errno_text());
        write_all(fd_, header.line() + "\n", path_);
        ::fsync(fd_);
    }
    last_sync_ = now_seconds();
}

TileJournal::~TileJournal() {
    if (fd_ < 0) return;
    try {
        sync();
    } catch (...) {
    }
    ::close(fd_);
}

void TileJournal::append(const TileOutput& tile) {
    std::lock_guard<std::mutex> lock(mutex_);
    append_tile_record(pending_, tile);
    if (now_seconds() - last_sync_ >= sync_seconds_) flush_locked();
}

void TileJournal::sync() {
    std::lock_guard<std::mutex> lock(mutex_);
    flush_locked();
}

void TileJournal::flush_locked() {
    if (fd_ < 0) return;
    write_all(fd_, pending_, path_);
    pending_.clear();
    ::fdatasync(fd_);
    last_sync_ = now_seconds();
}

void TileJournal::remove() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
    ::unlink(path_.c_str());
}

}  // namespace streamrt

namespace streamrt {

Framebuffer merge_parts(const std::vector<std::string>& paths, TileFileHeader& header) {
    if (paths.empty()) throw UsageError("merge: no parts given");
    std::optional<TileAssembly> assembly;
    std::vector<std::string> part_of;  // by shard number: the file that holds it
    for (const std::string& path : paths) {
        std::string data;
        if (!read_whole(path, data)) throw UsageError("merge: " + path + ": cannot read it: " + errno_text());
        const std::size_t nl = data.find('\n');
        const auto h = TileFileHeader::parse(std::string_view(data).substr(0, nl == std::string::npos ? 0 : nl));
        if (!h || h->shards == 0) throw UsageError("merge: " + path + ": not a streamrt shard part (streamrt --shard)");
        if (!assembly) {
            header = *h;
            assembly.emplace(h->width, h->height);
            part_of.assign(std::size_t(h->shards), std::string());
        } else if (!h->same_render(header) || h->shards != header.shards) {
            throw UsageError("merge: " + path + " does not belong with " + paths.front() + " (" +
                             (h->scene != header.scene ? "another scene" : "other settings or another shard count") +
                             ")");
        }
        std::string& owner = part_of[std::size_t(h->shard)];
        if (!owner.empty())
            throw UsageError("merge: " + path + " and " + owner + " are both part " + std::to_string(h->shard) + "/" +
                             std::to_string(h->shards));
        owner = path;
        const std::string_view records = std::string_view(data).substr(nl + 1);
        int placed = 0;
        bool foreign = false;
        const std::size_t valid = read_tile_records(records, h->width, h->height, [&](const TileOutput& t) {
            if (t.index % h->shards != h->shard || !assembly->place(t)) foreign = true;
            else ++placed;
        });
        const int expected = int(shard_tiles(h->tiles, h->shard, h->shards).size());
        if (foreign || valid != records.size() || placed != expected)
            throw UsageError("merge: " + path + ": part " + std::to_string(h->shard) + "/" + std::to_string(h->shards) +
                             " is incomplete or damaged (" + std::to_string(placed) + " of " +
                             std::to_string(expected) + " tiles)");
    }
    std::string missing;
    for (std::size_t k = 0; k < part_of.size(); ++k)
        if (part_of[k].empty()) missing += (missing.empty() ? "" : ", ") + std::to_string(k);
    if (!missing.empty())
        throw UsageError("merge: missing part(s) " + missing + " of " + std::to_string(header.shards));
    return std::move(assembly->image());
}

}  // namespace streamrt
