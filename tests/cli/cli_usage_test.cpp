// Command-line mistakes answered with the fix: the near option, an empty file name, a number
// that is not an integer, --profile json for --profile=json FILE (one line, exit status 2,
// nothing rendered).
#include <doctest/doctest.h>

#include <string>

#include "cli/cli_support.h"

using namespace cli_support;

// Proven against: main.cpp without kInteger, the empty-name check, the --profile json hint and
// parse_error_line (each message was CLI11's or none: -o "" rendered to the scene's output).
TEST_CASE("cli: usage mistakes name the fix") {
    Dir d;
    const fs::path scene = d.write("s.cfg", "image width=8 height=6 spp=1 output=" + (d.path / "scene_out.png").string() +
                                                "\nsphere\n");
    const auto refused = [&](const std::string& args, const std::string& message) {
        const Run r = run_streamrt(args);
        INFO("args: ", args);
        CHECK(r.code == 2);
        CHECK(r.err == "streamrt: " + message + "\n");
        CHECK(!fs::exists(d.path / "scene_out.png"));
    };
    refused(q(scene) + " -o ''", "-o: an empty file name (leave -o out to write the scene's output=)");
    refused(q(scene) + " --checkpoint ''", "--checkpoint: an empty file name");
    refused(q(scene) + " --spp 4.5", "--spp: '4.5' is not an integer (see --help)");
    refused(q(scene) + " -j 2x", "--jobs: '2x' is not an integer (see --help)");
    refused(q(scene) + " --width 1e3", "--width: '1e3' is not an integer (see --help)");
    refused(q(scene) + " --spp 0", "--spp: Value 0 not in range 1 to 65536 (see --help)");
    refused("--profile json prof.json " + q(scene),
            "--profile json: the format is joined to the option, --profile=json FILE (e.g. --profile=json prof.json)");
    refused(q(scene) + " --sp 4", "unknown option '--sp': did you mean '--spp'? (see --help)");
    refused(q(scene) + " --colourspace linear", "unknown option '--colourspace': did you mean '--colorspace'? (see --help)");
    refused(q(scene) + " --frobnicate", "The following argument was not expected: --frobnicate (see --help)");
    const fs::path colour = d.write("c.cfg", "sphere colour=1,0,0\n");
    const Run r = run_streamrt(q(colour));
    CHECK(r.code == 2);
    CHECK(r.err.rfind("streamrt: " + colour.string() + ":1:8: unknown key 'colour' for 'sphere': did you mean 'color'? "
                      "(expected one of: ", 0) == 0);
}

TEST_CASE("cli: --help names every image format -o writes") {
    // Written by hand, not from the format registry: .hdr worked and --help left it out.
    const Run r = run_streamrt("--help");
    CHECK(r.code == 0);
    CHECK(r.out.find("Output image (.ppm, .png, .pfm, .exr or .hdr); overrides the scene's") != std::string::npos);
    const Run m = run_streamrt("merge --help");
    CHECK(m.code == 0);
    CHECK(m.out.find("Output image (.ppm, .png, .pfm, .exr or .hdr)") != std::string::npos);
}
