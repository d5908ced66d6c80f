"""ctest python_package: pip installs the repository into a fresh virtual environment and renders.

    /usr/bin/python3 tests/python/check_package.py --build-dir build --streamrt build/engine/streamrt

A venv made with --system-site-packages (NumPy from Debian) in a temporary folder; pip
install --no-index --no-build-isolation of the repository (no network), its backend pointed
at this build folder (STREAMRT_BUILD_DIR) so only an out-of-date streamrt_python target is
built. Then, from the venv: the installed files; python -m streamrt against the program
(--version, a usage error, the PNG byte for byte, an .exr whose OpenEXR module must come from
the package folder); the Python API against python -m streamrt's PFM and against colours
known from the scene text. Not collected by pytest (python_module): it is not a test_*.py."""
import argparse
import os
import pathlib
import struct
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCENE = str(ROOT / "scenes/whitted.cfg")
SIZE = ["--width", "80", "--height", "60", "--spp", "1"]

# Run by the venv's interpreter: the API of the installed package.
IN_VENV = r"""
import pathlib, sys
import numpy as np
import streamrt

venv, pfm, exr = sys.argv[1:4]
assert streamrt.__file__.startswith(venv), streamrt.__file__

def read_pfm(path):
    data = pathlib.Path(path).read_bytes()
    magic, size, scale, rows = data.split(b"\n", 3)
    assert magic == b"PF" and float(scale) < 0
    w, h = map(int, size.split())
    return np.frombuffer(rows, "<f4", count=w * h * 3).reshape(h, w, 3)[::-1]

# The API's picture is python -m streamrt's PFM, bit for bit.
r = streamrt.render(%(scene)r, width=80, height=60, spp=1)
assert r.image.shape == (60, 80, 3) and r.image.dtype == np.float32
np.testing.assert_array_equal(r.image, read_pfm(pfm))
assert r.rays["primary"] == 80 * 60

# Degree 0: the flat colour of what a ray hits; a red sphere covers the centre, the
# corners see the blue background.
text = "image width=9 height=9 degree=0\nbackground 0,0,1\ncamera eye=0,0,5 look=0,0,0 fov=30\nsphere color=1,0,0\n"
img = streamrt.render(text).image
np.testing.assert_array_equal(img[4, 4], [1, 0, 0])
np.testing.assert_array_equal(img[0, 0], [0, 0, 1])

# Saving an .exr loads the OpenEXR module: the one installed beside the extension.
streamrt.save(r.image, exr)
maps = pathlib.Path("/proc/self/maps").read_text()
exr_modules = {line.split()[-1] for line in maps.splitlines() if line.endswith("libstreamrt_exr.so")}
assert exr_modules == {str(pathlib.Path(streamrt.__file__).parent / "libstreamrt_exr.so")}, exr_modules
print("api ok")
""" % {"scene": SCENE}


def png_size(path):
    data = pathlib.Path(path).read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and data[12:16] == b"IHDR", path
    return struct.unpack(">II", data[16:24])


def exr_data_window(path):
    """The dataWindow attribute of an OpenEXR header: (xmin, ymin, xmax, ymax)."""
    data = pathlib.Path(path).read_bytes()
    assert data[:4] == b"\x76\x2f\x31\x01", path
    pos = 8
    while data[pos] != 0:
        name_end = data.index(b"\0", pos)
        type_end = data.index(b"\0", name_end + 1)
        (size,) = struct.unpack("<i", data[type_end + 1:type_end + 5])
        value = data[type_end + 5:type_end + 5 + size]
        if data[pos:name_end] == b"dataWindow":
            return struct.unpack("<4i", value)
        pos = type_end + 5 + size
    raise AssertionError("no dataWindow in " + path)


def run(cmd, expect=0, **kw):
    p = subprocess.run([str(c) for c in cmd], capture_output=True, text=True, **kw)
    assert p.returncode == expect, "%s: exit %d, expected %d\n%s%s" % (cmd, p.returncode, expect, p.stdout, p.stderr)
    return p


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--build-dir", required=True, help="the CMake build folder pip's backend builds in")
    ap.add_argument("--streamrt", required=True, help="the program, for python -m streamrt to match")
    args = ap.parse_args()
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "STREAMRT_MODULE_DIR")}
    env["STREAMRT_BUILD_DIR"] = os.path.abspath(args.build_dir)
    start = time.monotonic()
    with tempfile.TemporaryDirectory(prefix="streamrt-package-") as tmp:
        tmp = pathlib.Path(tmp)
        venv = tmp / "venv"
        run([sys.executable, "-m", "venv", "--system-site-packages", venv])
        python = venv / "bin/python"
        # --isolated: no pip configuration of this machine's; --no-index: no network.
        made = time.monotonic()
        run([python, "-m", "pip", "--isolated", "install", "--no-index", "--no-build-isolation", ROOT], env=env)
        installed = time.monotonic()

        # The package's files, the type stubs and the modules it loads included.
        site = pathlib.Path(run([python, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                                cwd=tmp, env=env).stdout.strip())
        suffix = run([python, "-c", "import sysconfig; print(sysconfig.get_config_var('EXT_SUFFIX'))"],
                     cwd=tmp, env=env).stdout.strip()
        files = {p.name for p in (site / "streamrt").iterdir()}
        wanted = {"__init__.py", "__main__.py", "__init__.pyi", "py.typed", "_native" + suffix, "libstreamrt_exr.so"}
        assert wanted <= files, "missing from the installed package: %s" % sorted(wanted - files)

        # python -m streamrt is the command line: what the program prints and writes.
        module = [python, "-m", "streamrt"]
        version = run(module + ["--version"], cwd=tmp, env=env).stdout
        assert version == run([args.streamrt, "--version"]).stdout and version.startswith("streamrt "), version
        slip = run(module + [SCENE, "--sp", "2"], expect=2, cwd=tmp, env=env).stderr
        assert slip == "streamrt: unknown option '--sp': did you mean '--spp'? (see --help)\n", slip
        run(module + [SCENE, "-q", "-o", tmp / "m.png"] + SIZE, cwd=tmp, env=env)
        run([args.streamrt, SCENE, "-q", "-o", tmp / "p.png"] + SIZE)
        assert png_size(tmp / "m.png") == (80, 60)
        assert (tmp / "m.png").read_bytes() == (tmp / "p.png").read_bytes()
        summary = run(module + [SCENE, "-o", tmp / "m.exr"] + SIZE, cwd=tmp, env=env).stdout
        assert "80x60, spp 1" in summary and summary.rstrip().endswith("s)"), summary
        assert exr_data_window(tmp / "m.exr") == (0, 0, 79, 59)
        run(module + [SCENE, "-q", "-o", tmp / "m.pfm"] + SIZE, cwd=tmp, env=env)

        # The API of the installed package.
        out = run([python, "-c", IN_VENV, venv, tmp / "m.pfm", tmp / "api.exr"], cwd=tmp, env=env).stdout
        assert out == "api ok\n", out
        assert exr_data_window(tmp / "api.exr") == (0, 0, 79, 59)
    print("python_package: pip install, python -m streamrt and the API in a fresh venv: ok (venv %.1f s, pip "
          "install %.1f s, checks %.1f s)" % (made - start, installed - made, time.monotonic() - installed))


if __name__ == "__main__":
    main()
