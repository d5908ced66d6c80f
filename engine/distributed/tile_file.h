#pragma once
// Tiles that travel between processes and files: one binary record format for MPI messages,
// shard parts (streamrt --shard, streamrt merge) and checkpoint journals, and the header that
// binds a file to one scene and one set of render settings (docs/distributed.md).
#include <cstdint>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "driver/render.h"
#include "image/framebuffer.h"

namespace streamrt {

/// The first line of a tile file:
/// "streamrt-tiles 2 scene=HASH settings=S size=WxH tiles=T set=K/N\n" (set=all: every tile).
struct TileFileHeader {
    std::string scene;     ///< content hash of the scene's files (16 hex digits)
    std::string settings;  ///< everything else the pixels depend on: key=value,key=value...
    int width = 0, height = 0;
    int tiles = 0;         ///< tiles in the whole image
    int shard = -1, shards = 0;  ///< this file's tile set, K of N; -1/0: all tiles
    std::string line() const;
    /// Parses a header line (without the '\n'); nullopt when it is not one.
    static std::optional<TileFileHeader> parse(std::string_view line);
    /// The same scene, settings and tile count (not the tile set).
    bool same_render(const TileFileHeader& o) const {
        return scene == o.scene && settings == o.settings && width == o.width && height == o.height &&
               tiles == o.tiles;
    }
    /// The value of `key` in settings ("" if absent).
    std::string setting(std::string_view key) const;
};

/// The display settings a merge writes the image with, read back from a part's header (its
/// settings token, driver/render_job.h).
void apply_display_settings(const TileFileHeader& h, RenderSettings& s);

/// Reads shard parts (streamrt --shard) and puts the image together. Throws UsageError, one
/// line, when a part is unreadable, foreign (another scene, other settings, another N),
/// repeated, incomplete, or when a part is missing. `header` receives the common header.
Framebuffer merge_parts(const std::vector<std::string>& paths, TileFileHeader& header);

/// Appends a tile's record: index, ray counts, seconds, pixels and a checksum.
void append_tile_record(std::string& out, const TileOutput& tile);

/// Reads the records in `data` for a width x height image, handing each to `sink`; stops at
/// the first incomplete or damaged record (the torn end of an interrupted journal). Returns
/// the bytes of whole, valid records.
std::size_t read_tile_records(std::string_view data, int width, int height, const TileSink& sink);

/// The tile numbers of shard k of n: k, k + n, k + 2n, ... (interleaved, so each shard gets
/// a share of every part of the picture).
std::vector<int> shard_tiles(int tiles, int k, int n);

/// Parses "K/N" (0 <= K < N); throws UsageError otherwise.
void parse_shard(const std::string& text, int& k, int& n);

/// FNV-1a, 64 bits, as 16 hex digits.
std::uint64_t fnv1a(std::string_view bytes, std::uint64_t h = 1469598103934665603ull);
std::string hex64(std::uint64_t v);

/// The image being put together from tiles, in any order, from any source (thread-safe for
/// distinct tiles); knows which tiles it has and what they cost.
class TileAssembly {
  public:
    TileAssembly(int width, int height);
    /// Places a tile's pixels; false if that tile was already placed.
    bool place(const TileOutput& tile);
    bool has(int index) const { return placed_[std::size_t(index)] != 0; }
    int tiles() const { return int(placed_.size()); }
    int missing() const;
    RayCounts counts() const;
    Framebuffer& image() { return image_; }
    /// The records (append_tile_record) of the listed tiles, which must have been placed.
    std::string records(std::span<const int> tiles) const;
    /// "index,x0,y0,x1,y1,rays,seconds" per placed tile, for --tile-costs.
    std::string costs_csv() const;

  private:
    struct Cost {
        RayCounts counts;
        double seconds = 0;
    };
    Framebuffer image_;
    std::vector<unsigned char> placed_;
    std::vector<Cost> costs_;
    mutable std::mutex mutex_;
};

/// A checkpoint journal: the header, then one record per finished tile, appended as tiles
/// come in and flushed to disk (fsync) at most every `sync_seconds`.
class TileJournal {
  public:
    /// Opens `path`: with resume and a journal there, checks its header against `header`
    /// (UsageError naming what differs), places its tiles into `assembly`, and continues it;
    /// else starts a new one (UsageError if the file exists and resume is false).
    TileJournal(const std::string& path, const TileFileHeader& header, bool resume, TileAssembly& assembly,
                double sync_seconds = 2.0);
    ~TileJournal();
    TileJournal(const TileJournal&) = delete;
    TileJournal& operator=(const TileJournal&) = delete;
    void append(const TileOutput& tile);  ///< thread-safe
    void sync();                          ///< flushes now
    void remove();                        ///< after the image is written: the journal is done
    int resumed() const { return resumed_; }

  private:
    void flush_locked();  ///< writes what is pending and syncs; the mutex is held
    std::string path_;
    int fd_ = -1;
    int resumed_ = 0;
    double sync_seconds_;
    double last_sync_ = 0;
    std::string pending_;
    std::mutex mutex_;
};

}  // namespace streamrt
