#pragma once
// The small set of scene files the fuzz target's inputs may `include` by name; the
// regression test (tests/scene/fuzz_regressions_test.cpp) rebuilds the same tree so every
// saved input runs exactly as it did under the fuzzer.
#include <filesystem>
#include <fstream>
#include <string>

namespace streamrt_fuzz {

inline void write_file(const std::filesystem::path& p, const std::string& text) {
    std::ofstream(p, std::ios::binary) << text;
}

// A valid fragment, a chain, a self-cycle, a mutual cycle, a file with an error, a file in a
// sub-folder going back up, an empty file, a file including itself after two others, OBJ files.
inline void make_include_tree(const std::filesystem::path& dir) {
    std::filesystem::create_directories(dir / "sub");
    write_file(dir / "a.cfg", "material m color=1,0,0 refl=0.5 trans=0.5 ior=1.5\nlight point pos=0,5,0\n");
    write_file(dir / "b.cfg", "include a.cfg\nimage width=8 height=8\n");
    write_file(dir / "self.cfg", "include self.cfg\n");
    write_file(dir / "c1.cfg", "include c2.cfg\n");
    write_file(dir / "c2.cfg", "include c1.cfg\n");
    write_file(dir / "bad.cfg", "sphere scale=0\n");
    write_file(dir / "empty.cfg", "");
    write_file(dir / "sub" / "up.cfg", "include ../a.cfg\ncamera eye=0,0,5 look=0,0,0\n");
    write_file(dir / "twice.cfg", "include empty.cfg\ninclude empty.cfg\ninclude twice.cfg\n");
    // A tiny OBJ (two triangles, one quad) for `mesh file=tri.obj`.
    write_file(dir / "tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0.5\nf 1 2 3\nf 2 4 3\nf 1 2 4 3\n");
    // OBJ features for `mesh file=quad.obj` (materials=obj, textures): a library, quads,
    // relative indices, every corner form, CRLF, a comment; and a file with an index out of range.
    write_file(dir / "quad.obj",
               "mtllib quad.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0.25\nv 0 1 0\nv 2 0.5 0\nvt 0 0\nvt 1 0\nvt 1 1\n"
               "vt 0 1\nvn 0 0 1\nf 1/1/1 2/2/1 3/3/1 4/4/1\nusemtl red\nf -4/-4 -1/-1 -2/-2\r\n"
               "usemtl blue\nf 2//1 5//1 3//1 # tail\nf 1/1 5/2 3/3 4/4 2/1\n");
    write_file(dir / "quad.mtl", "newmtl red\nKd 1 0 0\nKs 0.5 0.5 0.5\nNs 20\nnewmtl blue\nKd 0 0 1\nd 0.5\nNi 1.3\n");
    write_file(dir / "bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\n");
    // The same in ASCII PLY, with normals and a property to skip, for `mesh file=tri.ply`.
    write_file(dir / "tri.ply",
               "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
               "property float nx\nproperty float ny\nproperty float nz\nproperty uchar red\nelement face 3\n"
               "property list uchar int vertex_indices\nend_header\n0 0 0 0 0 1 9\n1 0 0 0 0 1 9\n0 1 0 0 0 1 9\n"
               "1 1 0.5 0 0 1 9\n3 0 1 2\n3 1 3 2\n4 0 1 3 2\n");
}

}  // namespace streamrt_fuzz
