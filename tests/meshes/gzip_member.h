#pragma once
// One gzip member made with zlib's deflate (the gzip wrapper), the oracle of the tests that
// read compressed meshes (tests/meshes/gzip_mesh_test.cpp, tests/cli/memory_budget_test.cpp).
#include <doctest/doctest.h>
#include <zlib.h>

#include <string>

namespace streamrt::test {

/// `data` as one gzip member at compression `level` (zlib's 0 - 9, or Z_DEFAULT_COMPRESSION).
inline std::string gzip_member(const std::string& data, int level = Z_DEFAULT_COMPRESSION) {
    z_stream z{};
    REQUIRE(deflateInit2(&z, level, Z_DEFLATED, 16 + MAX_WBITS, 8, Z_DEFAULT_STRATEGY) == Z_OK);
    std::string out(deflateBound(&z, uLong(data.size())) + 64, '\0');
    z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data.data()));
    z.avail_in = uInt(data.size());
    z.next_out = reinterpret_cast<Bytef*>(out.data());
    z.avail_out = uInt(out.size());
    REQUIRE(deflate(&z, Z_FINISH) == Z_STREAM_END);
    out.resize(z.total_out);
    deflateEnd(&z);
    return out;
}

}  // namespace streamrt::test
