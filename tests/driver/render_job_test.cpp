// The settings record (driver/render_job.h): every field reaches the token that binds shard
// parts, checkpoint journals and frames, so renders that differ in any setting never mix.
#include <doctest/doctest.h>

#include <set>
#include <string>
#include <type_traits>

#include "core/error.h"
#include "driver/render_job.h"
#include "scene/parser.h"

using namespace streamrt;

namespace {

/// Another value of a field of any of the record's kinds.
template <class T>
T another(T v) {
    if constexpr (std::is_same_v<T, int>) return v + 1;
    else if constexpr (std::is_same_v<T, double>) return v * 2 + 1;
    else return T(int(v) == 0 ? 1 : 0);  // enums: every one has values 0 and 1
}

/// The record with its field number `which` changed (for_each_field's order).
PixelSettings with_field_changed(const PixelSettings& base, int which) {
    PixelSettings p = base;
    int i = 0;
    // for_each_field is const: find the field's address through it, then write it.
    base.for_each_field([&](const char*, const auto& value) {
        if (i++ != which) return;
        using T = std::decay_t<decltype(value)>;
        auto* field = reinterpret_cast<T*>(reinterpret_cast<char*>(&p) +
                                           (reinterpret_cast<const char*>(&value) - reinterpret_cast<const char*>(&base)));
        *field = another(value);
    });
    return p;
}

}  // namespace

// Proven against: a field left out of settings_token (cutoff: the token of the renders that
// differ in it is the same, the check names it).
TEST_CASE("settings record: every field is in the token, and changing any one changes it") {
    PixelSettings base;
    base.width = 64, base.height = 48, base.spp = 2, base.depth = 5, base.degree = 5;
    int fields = 0;
    std::set<std::string> names;
    base.for_each_field([&](const char* name, const auto&) {
        ++fields;
        names.insert(name);
    });
    CHECK(fields == PixelSettings::kFields);
    CHECK(names.size() == std::size_t(fields));  // distinct names
    const std::string token = settings_token(base);
    for (const std::string& n : names) CHECK(token.find(n + "=") != std::string::npos);
    for (int i = 0; i < fields; ++i) {
        CAPTURE(i);
        const PixelSettings changed = with_field_changed(base, i);
        CAPTURE(settings_token(changed));
        CHECK(settings_token(changed) != token);
    }
    // The recursive engine has no kernel level: its token does not depend on it.
    PixelSettings rec = base;
    rec.engine = EngineKind::Recursive;
    PixelSettings rec_other = rec;
    rec_other.isa = Isa::Avx2;
    CHECK(settings_token(rec) == settings_token(rec_other));
    CHECK(token.find("isa=sse2") != std::string::npos);
    // A build that computes pixels differently for the same settings writes another token.
    CHECK(token.rfind("pixels=6,width=64,", 0) == 0);
}

TEST_CASE("settings record: a job carries the overrides and the scene's own values") {
    const Scene sc = parse_scene("image width=40 height=30 spp=3 cutoff=0.25 sampler=grid\nsphere\n", "t.cfg");
    RenderOverrides o;
    REQUIRE(set_override(o, "spp", "5"));
    REQUIRE(set_override(o, "light_samples", "7"));
    REQUIRE(set_override(o, "tonemap", "reinhard"));
    CHECK_FALSE(set_override(o, "colour", "red"));
    CHECK_THROWS_AS(set_override(o, "sampler", "halton"), UsageError);
    const RenderJob job = build_render_job(std::make_shared<const Scene>(sc), o, false);
    CHECK(job.settings.width == 40);
    CHECK(job.settings.spp == 5);
    CHECK(job.render_settings.spp == 5);
    CHECK(job.scene->settings.spp == 3);  // the scene is not changed
    CHECK(job.settings.cutoff == 0.25);
    CHECK(job.settings.light_samples == 7);
    CHECK(job.settings.sampler == SamplePattern::Grid);
    CHECK(job.settings.tonemap == Tonemap::Reinhard);
    const std::string token = settings_token(job.settings);
    CHECK(token.rfind("pixels=6,width=40,height=30,spp=5,", 0) == 0);
    CHECK(token.find(",light_samples=7,") != std::string::npos);
    CHECK(token.find(",cutoff=0.25,") != std::string::npos);
    CHECK(token.find(",sampler=grid,") != std::string::npos);
    CHECK(token.find(",tonemap=reinhard,") != std::string::npos);
}
