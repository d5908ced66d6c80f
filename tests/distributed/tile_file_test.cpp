// Tiles across processes (engine/distributed): render_tiles in any order gives the picture
// of the whole-image render; tile records, headers, shards, journals and merging.
#include <doctest/doctest.h>

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/error.h"
#include "distributed/scene_bundle.h"
#include "distributed/tile_file.h"
#include "driver/render.h"
#include "scene/parser.h"

using namespace streamrt;
namespace fs = std::filesystem;

namespace {
const char* kScene =
    "image width=50 height=35 spp=2 depth=3 degree=5\n"
    "camera eye=0,1,6 look=0,0,0\n"
    "light point pos=5,8,5\nlight directional dir=0,-1,-1\n"
    "sphere refl=0.3 trans=0.5 ior=1.5\ncube translate=2,0,0 scale=0.5\nplane translate=0,-1,0 checker=0,0,0\n";

/// Renders the tiles in `order` into an assembly.
void render_in_order(TileAssembly& a, PreparedRender& prepared, Parallelism& par, const std::vector<int>& order) {
    render_tiles(prepared, par, std::span<const int>(order), [&](const TileOutput& t) { CHECK(a.place(t)); });
}

TileFileHeader header(const std::string& scene, const std::string& settings, int shard = -1, int shards = 0) {
    TileFileHeader h;
    h.scene = scene;
    h.settings = settings;
    h.width = 50;
    h.height = 35;
    h.tiles = 12;
    h.shard = shard;
    h.shards = shards;
    return h;
}

fs::path temp_path(const std::string& name) {
    return fs::temp_directory_path() / ("streamrt_tile_test_" + std::to_string(::getpid()) + "_" + name);
}
}  // namespace

TEST_CASE("distributed: tiles rendered in any order, on any thread count, give the whole-image picture") {
    const Scene sc = parse_scene(kScene, "t.cfg");
    const int tiles = tile_count(50, 35);
    CHECK(tiles == 4 * 3);
    std::vector<int> reversed;
    for (int i = tiles - 1; i >= 0; --i) reversed.push_back(i);
    for (EngineKind engine : {EngineKind::Stream, EngineKind::Recursive}) {
        Parallelism one(1), two(2);
        const RenderResult whole = render_scene(sc, engine, two);
        const auto prepared = prepare_render(sc, engine);
        TileAssembly a(50, 35);
        render_in_order(a, *prepared, one, reversed);
        CHECK(a.missing() == 0);
        CHECK(a.image().rgb == whole.image.rgb);
        CHECK(a.counts().total() == whole.counts.total());
        // Two interleaved shards on different thread counts, put together.
        TileAssembly b(50, 35);
        for (int k = 0; k < 2; ++k) {
            TileAssembly part(50, 35);
            render_in_order(part, *prepared, k ? two : one, shard_tiles(tiles, k, 2));
            const std::string records = part.records(shard_tiles(tiles, k, 2));
            CHECK(read_tile_records(records, 50, 35, [&](const TileOutput& t) { CHECK(b.place(t)); }) == records.size());
        }
        CHECK(b.image().rgb == whole.image.rgb);
    }
}

TEST_CASE("distributed: tile records stop at a torn or damaged end") {
    const Scene sc = parse_scene(kScene, "t.cfg");
    Parallelism par(2);
    const auto prepared = prepare_render(sc, EngineKind::Stream);
    TileAssembly a(50, 35);
    render_in_order(a, *prepared, par, shard_tiles(12, 0, 1));
    const std::string all = a.records(shard_tiles(12, 0, 1));
    int seen = 0;
    const auto count = [&](const TileOutput&) { ++seen; };
    CHECK(read_tile_records(all, 50, 35, count) == all.size());
    CHECK(seen == 12);
    seen = 0;
    const std::size_t cut = read_tile_records(all.substr(0, all.size() - 3), 50, 35, count);
    CHECK(seen == 11);
    CHECK(cut < all.size());
    std::string damaged = all;
    damaged[cut + 60] ^= 1;  // a pixel of the last record
    seen = 0;
    CHECK(read_tile_records(damaged, 50, 35, count) == cut);
    CHECK(seen == 11);
}

TEST_CASE("distributed: headers, shard sets and K/N") {
    const TileFileHeader h = header("0123456789abcdef", "spp=4,calibration=clamp", 2, 5);
    const auto back = TileFileHeader::parse(h.line());
    REQUIRE(back);
    CHECK(back->line() == h.line());
    CHECK(back->setting("spp") == "4");
    CHECK(back->setting("calibration") == "clamp");
    CHECK(back->setting("sp") == "");
    CHECK_FALSE(TileFileHeader::parse("P6 50 35"));
    CHECK_FALSE(TileFileHeader::parse(h.line().replace(h.line().find("tiles=12"), 8, "tiles=13")));
    CHECK(shard_tiles(12, 2, 5) == std::vector<int>{2, 7});
    int k = 0, n = 0;
    parse_shard("3/4", k, n);
    CHECK((k == 3 && n == 4));
    for (const char* bad : {"3/2", "0/0", "4/4", "-1/2", "1/", "/2", "a/b", "1/2/3"})
        CHECK_THROWS_AS(parse_shard(bad, k, n), UsageError);
}

TEST_CASE("distributed: a journal resumes its tiles and refuses another render's") {
    const Scene sc = parse_scene(kScene, "t.cfg");
    Parallelism par(2);
    const auto prepared = prepare_render(sc, EngineKind::Stream);
    const RenderResult whole = render_scene(sc, EngineKind::Stream, par);
    const TileFileHeader h = header("00000000000000aa", "spp=2");
    const fs::path path = temp_path("journal");
    fs::remove(path);
    {
        TileAssembly a(50, 35);
        TileJournal j(path.string(), h, false, a);
        render_tiles(*prepared, par, std::span<const int>(shard_tiles(12, 0, 2)), [&](const TileOutput& t) {
            a.place(t);
            j.append(t);
        });
    }  // closed: flushed
    CHECK_THROWS_AS(TileJournal(path.string(), h, false, *std::make_unique<TileAssembly>(50, 35)), UsageError);
    TileFileHeader other = h;
    other.settings = "spp=3";
    CHECK_THROWS_WITH_AS(TileJournal(path.string(), other, true, *std::make_unique<TileAssembly>(50, 35)),
                         doctest::Contains("other settings"), UsageError);
    other = h;
    other.scene = "00000000000000bb";
    CHECK_THROWS_WITH_AS(TileJournal(path.string(), other, true, *std::make_unique<TileAssembly>(50, 35)),
                         doctest::Contains("another scene"), UsageError);
    TileAssembly a(50, 35);
    {
        TileJournal j(path.string(), h, true, a);
        CHECK(j.resumed() == 6);
        std::vector<int> rest;
        for (int i = 0; i < 12; ++i)
            if (!a.has(i)) rest.push_back(i);
        CHECK(rest == shard_tiles(12, 1, 2));
        render_tiles(*prepared, par, std::span<const int>(rest), [&](const TileOutput& t) {
            a.place(t);
            j.append(t);
        });
        j.remove();
    }
    CHECK(a.image().rgb == whole.image.rgb);
    CHECK_FALSE(fs::exists(path));
}

TEST_CASE("distributed: a scene bundle reads the same scene elsewhere, includes and meshes with it") {
    const std::string scene = std::string(STREAMRT_SOURCE_DIR) + "/scenes/meshes/mesh.cfg";
    SceneBundle bundle;
    const Scene a = load_scene_bundled(scene, 1, bundle);
    CHECK(bundle.files.size() >= 2);  // the scene and its OBJ file
    const SceneBundle copy = SceneBundle::deserialize(bundle.serialize());
    CHECK(copy.content_hash() == bundle.content_hash());
    const Scene b = load_scene_from_bundle(copy, 1);
    CHECK(b.objects.size() == a.objects.size());
    CHECK(b.meshes.size() == a.meshes.size());
    Parallelism par(2);
    CHECK(render_scene(a, EngineKind::Stream, par).image.rgb == render_scene(b, EngineKind::Stream, par).image.rgb);
    SceneBundle changed = copy;
    changed.files.back().bytes += "\n";
    CHECK(changed.content_hash() != bundle.content_hash());
}
