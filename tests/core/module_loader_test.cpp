// Modules loaded on first use (core/module_loader.h): found beside the build's programs,
// $STREAMRT_MODULE_DIR first, and a clear message naming the folders when one is missing.
#include <doctest/doctest.h>

#include <cstdlib>
#include <string>

#include "core/module_loader.h"
#include "image/exr_codec.h"

using namespace streamrt;

TEST_CASE("modules: the OpenEXR module is found from the test program and has this version") {
    std::string error;
    void* entry = module_symbol(kExrModuleFile, kExrCodecSymbol, false, error);
    REQUIRE_MESSAGE(entry != nullptr, error);
    const ExrCodec* codec = reinterpret_cast<const ExrCodec* (*)()>(entry)();
    CHECK(codec->version == kExrCodecVersion);
    CHECK(bool(codec->write));
    CHECK(bool(codec->read));
    // build/tests/streamrt_tests looks in build/lib/streamrt/.
    const std::string path = module_search_path();
    CHECK(path.find("/lib/streamrt") != std::string::npos);
}

TEST_CASE("modules: a missing module or symbol gives no address and a message naming the folders") {
    setenv("STREAMRT_MODULE_DIR", "/nonexistent/streamrt-modules", 1);
    std::string error;
    CHECK(module_symbol("libstreamrt_absent.so", "anything", false, error) == nullptr);
    CHECK(error.rfind("libstreamrt_absent.so not found in /nonexistent/streamrt-modules:", 0) == 0);
    CHECK(module_search_path().rfind("/nonexistent/streamrt-modules:", 0) == 0);
    error.clear();
    CHECK(module_symbol(kExrModuleFile, "streamrt_no_such_entry", false, error) == nullptr);
    CHECK(error.find("has no streamrt_no_such_entry") != std::string::npos);
    unsetenv("STREAMRT_MODULE_DIR");
    CHECK(module_search_path().find("/nonexistent/") == std::string::npos);
}
