// libFuzzer target for the whole load-validate path: parse_scene() on arbitrary bytes (with
// `include` resolved inside a private temporary folder holding a few small scene files,
// tests/fuzz/include_tree.h), then the checks the command line makes before rendering
// (camera placement for the image size, the memory estimate). Built and run by
// scripts/fuzz.sh. Beyond "no crash, no sanitizer report" it asserts the parser's contract
// (tests/fuzz/scene_contract.h) and aborts when it is broken.
#include <unistd.h>

#include <cstdint>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <string_view>

#include "fuzz/include_tree.h"
#include "fuzz/scene_contract.h"
#include "scene/parser.h"

namespace {
namespace fs = std::filesystem;
std::string g_name;  // the fuzz input's file name, inside the temporary folder

void require(const std::string& broken) {
    if (broken.empty()) return;
    std::fprintf(stderr, "scene_fuzz: contract broken: %s\n", broken.c_str());
    std::abort();
}
}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
    char tmpl[] = "/tmp/streamrt_fuzz_XXXXXX";
    if (!::mkdtemp(tmpl)) std::abort();
    static const fs::path dir(tmpl);
    streamrt_fuzz::make_include_tree(dir);
    std::atexit([] {
        std::error_code ec;
        fs::remove_all(dir, ec);
    });
    // Relative includes resolve against the input's folder (the working directory is left
    // alone: libFuzzer writes its artifacts relative to it).
    g_name = (dir / "input.cfg").string();
    return 0;
}

/// What a read gives, in short: the error's text, or the objects' kinds and lines.
std::string outcome(std::string_view text, const streamrt::ReadOptions& options) {
    try {
        const streamrt::Scene sc = streamrt::parse_scene(text, g_name, options);
        std::string out = "ok";
        for (std::size_t i = 0; i < sc.objects.size(); ++i)
            out += " " + std::to_string(int(sc.objects[i].kind)) + "@" + std::to_string(sc.where(i).line) + "m" +
                   std::to_string(sc.objects[i].material);
        return out;
    } catch (const streamrt::SceneError& e) {
        return e.what();
    }
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    try {
        const streamrt::Scene sc = streamrt::parse_scene(text, g_name);
        require(streamrt_fuzz::check_scene(sc));
    } catch (const streamrt::SceneError& e) {
        require(streamrt_fuzz::check_error(e));
    }
    // The chunked reader (tiny chunks, one thread) must say exactly what one pass says.
    streamrt::ReadOptions one_pass, chunked;
    one_pass.chunked_from = SIZE_MAX;
    chunked.jobs = 1;
    chunked.chunk_bytes = 5;
    chunked.chunked_from = 0;
    const std::string a = outcome(text, one_pass), b = outcome(text, chunked);
    if (a != b) require("chunked read differs: '" + b + "' instead of '" + a + "'");
    return 0;
}
