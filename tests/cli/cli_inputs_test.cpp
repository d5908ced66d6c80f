// The command line never writes over a file the scene read (the scene file, includes, meshes,
// material libraries, textures): every file it would write is checked by identity before
// rendering, and refused with one line naming the option or the scene key (exit status 2).
#include <doctest/doctest.h>

#include <string>

#include "cli/cli_support.h"
#include "scene/test_png.h"

using namespace cli_support;

namespace {

/// A scene that reads one file of each kind, each in its own folder:
///   line 2 includes parts/inc.cfg (column 9), line 3 reads the texture tex/w2.png (column 23),
///   line 5 reads the mesh m/two.obj (column 11), its library m/two.mtl and its texture m/skin.png.
struct InputsScene {
    Dir d;
    fs::path scene, inc, tex, obj, mtl, skin;
    InputsScene() {
        fs::create_directories(d.path / "parts");
        fs::create_directories(d.path / "tex");
        fs::create_directories(d.path / "m");
        scene = d.write("s.cfg",
                        "image width=8 height=6 spp=1 depth=0 degree=1\n"
                        "include parts/inc.cfg\n"
                        "material wood texture=tex/w2.png\n"
                        "sphere material=wood\n"
                        "mesh file=m/two.obj materials=obj\n");
        inc = d.write("parts/inc.cfg", "camera eye=0,0,6 look=0,0,0\n");
        tex = d.path / "tex" / "w2.png";
        streamrt::test::write_png(tex.string(), 2, 2, streamrt::test::kQuad);
        obj = d.write("m/two.obj", "mtllib two.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\n"
                                   "usemtl skin\nf 1/1 2/2 3/3\n");
        mtl = d.write("m/two.mtl", "newmtl skin\nKd 1 1 1\nmap_Kd skin.png\n");
        skin = d.path / "m" / "skin.png";
        streamrt::test::write_png(skin.string(), 2, 2, streamrt::test::kQuad);
    }
    std::string at(int line, int col) const { return scene.string() + ":" + std::to_string(line) + ":" + std::to_string(col); }
};

/// Refused with exactly `message`, exit status 2, and nothing the scene read changed.
void check_refused(const InputsScene& s, const Run& r, const std::string& message) {
    INFO("stderr: ", r.err);
    CHECK(r.code == 2);
    CHECK(r.err == "streamrt: " + message + "\n");
    CHECK(r.out.empty());
    CHECK(slurp(s.inc) == "camera eye=0,0,6 look=0,0,0\n");
    CHECK(slurp(s.mtl) == "newmtl skin\nKd 1 1 1\nmap_Kd skin.png\n");
    CHECK(slurp(s.tex) == slurp(s.skin));  // both still the same 2x2 PNG
    CHECK(slurp(s.tex).substr(1, 3) == "PNG");
}

}  // namespace

// Proven against: the check skipped in make_job (cli/job.cpp): the texture was rendered over, exit 0.
TEST_CASE("cli: an output that is one of the scene's inputs is refused before rendering") {
    InputsScene s;
    const std::string scene = q(s.scene);
    SUBCASE("the scene renders when the output is a new file") {
        const Run r = run_streamrt("-q " + scene + " -o " + q(s.d.path / "fresh.png"));
        CHECK(r.code == 0);
        CHECK(fs::exists(s.d.path / "fresh.png"));
    }
    SUBCASE("-o a texture, under any spelling or link") {
        const std::string why = ": is an input of the scene (texture named at " + s.at(3, 23) + ")";
        check_refused(s, run_streamrt(scene + " -o " + q(s.tex)), "-o " + s.tex.string() + why);
        // Another spelling of the same path, a hard link: the same device and inode.
        const fs::path spelled = s.d.path / "m" / ".." / "tex" / "." / "w2.png";
        check_refused(s, run_streamrt(scene + " -o " + q(spelled)), "-o " + spelled.string() + why);
        fs::create_hard_link(s.tex, s.d.path / "link.png");
        check_refused(s, run_streamrt(scene + " -o " + q(s.d.path / "link.png")),
                      "-o " + (s.d.path / "link.png").string() + why);
        // --check validates the output too; --shard writes a part under the same name.
        check_refused(s, run_streamrt("--check " + scene + " -o " + q(s.tex)), "-o " + s.tex.string() + why);
        check_refused(s, run_streamrt(scene + " --shard 0/2 -o " + q(s.tex)), "-o " + s.tex.string() + why);
    }
    SUBCASE("-o a texture of the OBJ file's material library") {
        check_refused(s, run_streamrt(scene + " -o " + q(s.skin)),
                      "-o " + s.skin.string() + ": is an input of the scene (texture named at " + s.at(5, 11) + ")");
    }
    SUBCASE("one frame's name of --frames") {
        const std::string pattern = (s.d.path / "tex" / "w%d.png").string();
        check_refused(s, run_streamrt(scene + " --frames 0..3 -o " + q(pattern)),
                      "-o " + pattern + " (as " + s.tex.string() + "): is an input of the scene (texture named at " +
                          s.at(3, 23) + ")");
        CHECK(!fs::exists(s.d.path / "tex" / "w0.png"));  // frames before the clash are not rendered either
    }
    SUBCASE("the files beside the image") {
        const std::string out = " -o " + q(s.d.path / "o.png");
        check_refused(s, run_streamrt(scene + out + " --checkpoint " + q(s.inc)),
                      "--checkpoint " + s.inc.string() + ": is an input of the scene (included file named at " +
                          s.at(2, 9) + ")");
        check_refused(s, run_streamrt(scene + out + " --tile-costs " + q(s.mtl)),
                      "--tile-costs " + s.mtl.string() + ": is an input of the scene (material library named at " +
                          s.at(5, 11) + ")");
        check_refused(s, run_streamrt(scene + out + " --profile=json " + q(s.obj)),
                      "--profile=json " + s.obj.string() + ": is an input of the scene (mesh named at " + s.at(5, 11) +
                          ")");
        check_refused(s, run_streamrt(scene + " --tile-costs " + q(s.scene) + out),
                      "--tile-costs " + s.scene.string() + ": is an input of the scene (the scene file)");
        // The sample map must be .pfm or .exr: a scene file of that name, refused as itself.
        const fs::path pfm_scene = s.d.write("scene.pfm", slurp(s.scene));
        check_refused(s, run_streamrt(q(pfm_scene) + " --adaptive 0.1 --spp 4" + out + " --aov samples=" + q(pfm_scene)),
                      "--aov samples=" + pfm_scene.string() + ": is an input of the scene (the scene file)");
        CHECK(slurp(pfm_scene) == slurp(s.scene));
        CHECK(!fs::exists(s.d.path / "o.png"));
    }
    SUBCASE("the scene's own output= is reported at its key") {
        // output= is relative to the working folder (docs/scene-format.md, "Paths"): absolute here.
        const fs::path own = s.d.write("own.cfg", "include parts/inc.cfg\nimage width=8 height=6 output=" +
                                                      s.inc.string() + "\n");
        check_refused(s, run_streamrt(q(own)),
                      own.string() + ":2:31: output=" + s.inc.string() +
                          ": is an input of the scene (included file named at " + own.string() + ":1:9)");
    }
}

// Proven against: run_merge without the parts check (cli/tiled.cpp): the part was merged over itself, exit 0.
TEST_CASE("cli: merge refuses an output that is one of its parts") {
    Dir d;
    const fs::path scene = d.write("s.cfg", "image width=8 height=6 spp=1\nsphere\n");
    // A part may have any name (docs/distributed.md), an image's too.
    const fs::path part = d.path / "p.png";
    REQUIRE(run_streamrt("-q " + q(scene) + " --shard 0/1 -o " + q(part)).code == 0);
    const std::string bytes = slurp(part);
    const Run r = run_streamrt("merge " + q(part) + " -o " + q(d.path / "." / "p.png"));
    CHECK(r.code == 2);
    CHECK(r.err == "streamrt: -o " + (d.path / "." / "p.png").string() + ": is one of the parts being merged\n");
    CHECK(slurp(part) == bytes);
    const Run ok = run_streamrt("merge -q " + q(part) + " -o " + q(d.path / "whole.png"));
    CHECK(ok.code == 0);
    CHECK(slurp(d.path / "whole.png").substr(1, 3) == "PNG");
}
