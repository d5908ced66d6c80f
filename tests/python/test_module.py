"""The streamrt Python module (docs/python.md), run by ctest with Debian's pytest.

Every expected value comes from outside the module: the command line's PFM, files parsed here,
or values worked out from the scene text."""
import json
import os
import pathlib
import signal
import subprocess
import tempfile

import numpy as np
import pytest

import streamrt

ROOT = pathlib.Path(__file__).resolve().parents[2]
STREAMRT = os.environ.get("STREAMRT_BINARY", str(ROOT / "build/engine/streamrt"))
WHITTED = str(ROOT / "scenes/whitted.cfg")
RANDOM_SPHERES = str(ROOT / "scenes/random_spheres.cfg")


def read_pfm(path):
    """A PFM read here, independently of the engine: header, then rows from the bottom."""
    data = pathlib.Path(path).read_bytes()
    parts = data.split(b"\n", 3)
    assert parts[0] == b"PF"
    width, height = map(int, parts[1].split())
    assert float(parts[2]) < 0  # little-endian
    rows = np.frombuffer(parts[3], dtype="<f4", count=width * height * 3).reshape(height, width, 3)
    return rows[::-1]


def cli_pfm(scene, *args):
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, "x.pfm")
        subprocess.run([STREAMRT, scene, "-q", "-o", out, *args], check=True)
        return read_pfm(out)


def cli_profile(scene, *args):
    """The --profile=json of a command-line render, read here."""
    with tempfile.TemporaryDirectory() as d:
        out, prof = os.path.join(d, "x.pfm"), os.path.join(d, "p.json")
        subprocess.run([STREAMRT, scene, "-q", "-o", out, "--profile=json", prof, *args], check=True)
        return json.loads(pathlib.Path(prof).read_text())


def test_image_is_the_command_lines_pfm_bit_for_bit():
    r = streamrt.render(WHITTED, width=96, height=64, spp=2)
    assert r.image.shape == (64, 96, 3)
    assert r.image.dtype == np.float32
    np.testing.assert_array_equal(r.image, cli_pfm(WHITTED, "--width", "96", "--height", "64", "--spp", "2"))
    assert r.engine == "stream"
    assert r.rays["primary"] == 96 * 64 * 2
    assert set(r.seconds) == {"read", "setup", "render"}


@pytest.mark.parametrize(
    "overrides, flags",
    [
        (dict(depth=1, degree=3), ["--depth", "1", "--degree", "3"]),
        (dict(sampler="random", spp=3), ["--sampler", "random", "--spp", "3"]),
        (dict(cutoff=0.05), ["--cutoff", "0.05"]),
        (dict(engine="recursive"), ["--engine", "recursive"]),
        (dict(isa="sse2", accel="bvh"), ["--isa", "sse2", "--accel", "bvh"]),
        (dict(accel="flat", threads=1), ["--accel", "flat", "-j", "1"]),
        (dict(adaptive=0.01, spp=16), ["--adaptive", "0.01", "--spp", "16"]),
    ],
)
def test_overrides_give_the_command_lines_picture(overrides, flags):
    size = dict(width=48, height=32)
    r = streamrt.render(WHITTED, **size, **overrides)
    np.testing.assert_array_equal(r.image, cli_pfm(WHITTED, "--width", "48", "--height", "32", *flags))


def test_accel_and_threads_reach_the_engine():
    # Every accel and thread count gives the same picture, so the picture alone passed with both
    # options ignored. The profile names what ran: random_spheres.cfg's spheres take the
    # hierarchy by default (its intersect stage lists no kinds), the flat loop over kinds with
    # accel="flat"; and the threads.
    size = dict(width=48, height=32)
    r = streamrt.render(RANDOM_SPHERES, **size, accel="flat", threads=1, profile=True)
    want = cli_profile(RANDOM_SPHERES, "--width", "48", "--height", "32", "--accel", "flat", "-j", "1")
    assert r.profile["threads"] == want["threads"] == 1
    assert "intersect[sphere,plane]" in r.profile["built"]
    assert r.profile["built"] == want["built"]
    assert "intersect[]" in streamrt.render(RANDOM_SPHERES, **size, profile=True).profile["built"]


def test_adaptive_result_carries_the_sample_map_of_the_command_line():
    r = streamrt.render(WHITTED, width=48, height=32, spp=16, adaptive=0.01)
    assert r.adaptive is not None
    with tempfile.TemporaryDirectory() as d:
        out, samples = os.path.join(d, "x.pfm"), os.path.join(d, "n.pfm")
        subprocess.run([STREAMRT, WHITTED, "-q", "-o", out, "--width", "48", "--height", "32", "--spp", "16",
                        "--adaptive", "0.01", "--aov", "samples=" + samples], check=True)
        np.testing.assert_array_equal(r.adaptive["sample_map"], read_pfm(samples))
    counts = r.adaptive["sample_map"][..., 0]
    assert set(np.unique(counts)) <= {4.0, 8.0, 16.0}
    # The first round is the pixels' 49 x 33 corners, each traced once and counted in each of the
    # (up to four) pixels it bounds; later rounds are the pixel's own: camera rays per pixel.
    corners, later = 49 * 33, int((counts - 4).sum())
    assert r.rays["primary"] == corners + later
    assert r.adaptive["mean_spp"] == pytest.approx((corners + later) / (48 * 32))
    # Rounds: the corners, then 4, 8 more samples; 3 since some pixel took 16.
    assert counts.max() == 16.0 and r.adaptive["rounds"] == 3
    assert set(r.adaptive["seconds"]) == {"corners", "neighbour_rule", "rounds", "final_pass"}
    assert all(v >= 0 for v in r.adaptive["seconds"].values())
    p = streamrt.render(WHITTED, width=48, height=32, spp=16, adaptive=0.01, profile=True).profile
    assert p["adaptive"]["rounds"] == 3 and p["adaptive"]["cap"] == 16
    assert p["adaptive"]["mean_spp"] == pytest.approx(r.adaptive["mean_spp"], abs=1e-6)
    assert streamrt.render(WHITTED, width=48, height=32, spp=16).adaptive is None


def test_adaptive_result_says_what_cut_the_request_short():
    size = dict(width=48, height=32)
    a = streamrt.render(WHITTED, **size, spp=4, target_error=0.0001).adaptive
    assert (a["cut_short_by"], a["cap"], a["cap_from"]) == ("cap", 4, "spp")
    # Pixels at the cap above their stopping point T (n / 16)^(3/4), counted here from the
    # sample map (within 0.1 % of the point the map's float error may fall either side).
    counts, errors = a["sample_map"][..., 0], a["sample_map"][..., 1]
    point = 0.0001 * (4 / 16) ** 0.75
    surely = int(((counts == 4) & (errors > point * 1.001)).sum())
    maybe = int(((counts == 4) & (errors > point * 0.999)).sum())
    assert 0 < surely <= a["above_at_cap"] <= maybe
    with tempfile.TemporaryDirectory() as d:
        line = subprocess.run([STREAMRT, WHITTED, "-o", os.path.join(d, "x.pfm"), "--width", "48", "--height", "32",
                               "--spp", "4", "--target-error", "0.0001"], check=True, capture_output=True, text=True).stdout
    assert f"target error 0.0001 not reached: {a['above_at_cap']} pixel(s) stopped at the cap of 4 samples (--spp)" in line
    # Without spp the scene's uniform 4 is no cap: 64, and a coarse target is met.
    met = streamrt.render(WHITTED, **size, target_error=0.2).adaptive
    assert (met["cut_short_by"], met["cap"], met["cap_from"]) == (None, 64, "default")
    timed = streamrt.render(WHITTED, **size, target_error=0.0001, time_limit=1e-9).adaptive
    assert timed["cut_short_by"] == "time_limit" and timed["time_limited"]
    coarse = streamrt.render(WHITTED, **size, spp=64, target_error=0.0001, adaptive=0.9).adaptive
    assert coarse["cut_short_by"] == "threshold" and coarse["above_at_cap"] == 0


def test_a_one_line_cfg_name_that_is_no_file_is_no_such_file():
    missing = str(ROOT / "scenes/whited.cfg")
    with pytest.raises(FileNotFoundError) as e:
        streamrt.render(missing)
    assert e.value.filename == missing
    # Without the .cfg ending one line is still scene text, read and refused as such.
    with pytest.raises(streamrt.SceneError, match="unknown statement 'whited'"):
        streamrt.render("whited")


def test_scene_text_and_flat_colours():
    # Degree 0: the flat colour of what a ray hits. A red sphere in front of the camera
    # covers the centre; the corners see the background.
    text = "image width=9 height=9 degree=0\nbackground 0,0,1\ncamera eye=0,0,5 look=0,0,0 fov=30\nsphere color=1,0,0\n"
    img = streamrt.render(text).image
    np.testing.assert_array_equal(img[4, 4], [1, 0, 0])
    np.testing.assert_array_equal(img[0, 0], [0, 0, 1])


def test_a_csg_block_from_python_cuts_a_hole():
    # A pipe seen down its axis at degree 0: a cylinder of radius 1 minus one of radius 0.5
    # (the inner one longer, so it opens both ends). The camera at z = 5 looks down the
    # axis (fov 30: the half-width at the pipe's near end, 4 away, is 4 tan 15 = 1.07):
    # the centre pixel sees the background through the hole, a pixel at x = 0.75 the pipe.
    scene = streamrt.Scene()
    scene.add("image width=15 height=15 degree=0\nbackground 0,0,1\ncamera eye=0,0,5 look=0,0,0 fov=30")
    with scene.csg("difference", color=(1, 0, 0), rotate_x=90) as block:
        assert block is scene
        scene.statement("cylinder")
        scene.statement("cylinder", scale=(0.5, 1.5, 0.5), color=(0, 1, 0))
    assert scene.text.splitlines()[-4:] == [
        "csg difference color=1,0,0 rotate_x=90", "cylinder", "cylinder scale=0.5,1.5,0.5 color=0,1,0", "end"]
    img = streamrt.render(scene, engine="recursive").image
    np.testing.assert_array_equal(img[7, 7], [0, 0, 1])  # down the hole
    np.testing.assert_array_equal(img[7, 12], [1, 0, 0])  # the pipe's end face, x = 0.75 at z = 1
    # A block whose body raised is still closed, and the scene reader refuses a bad operation
    # at its line and column.
    bad = streamrt.Scene()
    with pytest.raises(RuntimeError):
        with bad.csg("unoin"):
            raise RuntimeError("stop")
    assert bad.text == "csg unoin\nend\n"
    with pytest.raises(streamrt.SceneError) as e:
        streamrt.render(bad)
    assert (e.value.line, e.value.column) == (1, 5)


def test_scene_errors_carry_file_line_and_column():
    with pytest.raises(streamrt.SceneError) as e:
        streamrt.render("image width=9\nsphere colour=1,0,0\n")
    assert (e.value.file, e.value.line, e.value.column) == ("<string>", 2, 8)
    assert "unknown key 'colour'" in e.value.message
    assert str(e.value).startswith("<string>:2:8: unknown key 'colour'")
    with pytest.raises(TypeError, match="unexpected keyword argument 'spp_'"):
        streamrt.render(WHITTED, spp_=2)
    with pytest.raises(ValueError, match="sampler"):
        streamrt.render(WHITTED, sampler="halton")
    with pytest.raises(ValueError, match="spp must be in"):
        streamrt.render(WHITTED, spp=0)


def test_profile_is_the_json_of_the_command_line():
    r = streamrt.render(WHITTED, width=32, height=32, threads=2, profile=True)
    assert r.profile is not None
    # The command line's own --profile=json: the same fields and every figure that is not a
    # time (the rays of each stage and generation, the pipeline, the level, the lanes).
    cli = cli_profile(WHITTED, "--width", "32", "--height", "32", "-j", "2")
    assert set(r.profile) == set(cli)
    for key in ("isa", "lanes", "threads", "built", "rays"):
        assert r.profile[key] == cli[key], key

    def untimed(rows):
        return [{k: v for k, v in row.items() if "seconds" not in k and "mrays" not in k} for row in rows]
    assert untimed(r.profile["stages"]) == untimed(cli["stages"])
    assert untimed(r.profile["generations"]) == untimed(cli["generations"])
    # the per-generation rows split the intersect and occlusion stages
    gens = r.profile["generations"]
    stages = {s["stage"]: s for s in r.profile["stages"]}
    assert gens[0]["generation"] == 0 and gens[0]["rays"] == gens[0]["primary"] == r.profile["rays"]["primary"]
    assert sum(g["rays"] for g in gens) == stages["intersect"]["rays_in"]
    assert sum(g["shadow_rays"] for g in gens) == r.profile["rays"]["shadow"]
    assert streamrt.render(WHITTED, width=32, height=32).profile is None


def test_progress_reaches_every_tile():
    # The closing call carries the tiles the render counted (it was (total, total) whatever
    # the render did): uniform, and adaptive, whose first round traces blocks of 2 x 2 tiles.
    for adaptive in ({}, dict(spp=16, adaptive=0.01)):
        seen = []
        streamrt.render(WHITTED, width=64, height=48, progress=lambda done, total: seen.append((done, total)), **adaptive)
        assert seen[-1] == (12, 12), adaptive  # 64x48 in 16x16 tiles
        assert all(d <= t for d, t in seen)
        assert all(a[0] <= b[0] for a, b in zip(seen, seen[1:]))


def test_ctrl_c_cancels_the_render_and_raises_keyboard_interrupt():
    # Far too big to finish: the interrupt (sent at the first progress report) must stop it.
    calls = []

    def interrupt(done, total):
        calls.append((done, total))
        if len(calls) == 1:
            os.kill(os.getpid(), signal.SIGINT)

    with pytest.raises(KeyboardInterrupt):
        streamrt.render(WHITTED, width=4096, height=4096, spp=64, progress=interrupt)
    assert len(calls) == 1  # nothing reported after the interrupt: the render stopped
    assert calls[0][0] < calls[0][1]


def test_compare_and_save_round_trip(tmp_path):
    c = streamrt.compare(WHITTED, width=48, height=32)
    assert c["stream"].engine == "stream" and c["recursive"].engine == "recursive"
    assert c["psnr"] > 50
    rmse = float(np.sqrt(np.mean((np.clip(c["stream"].image, 0, 1) - np.clip(c["recursive"].image, 0, 1)) ** 2)))
    assert c["rmse"] == pytest.approx(rmse, rel=1e-6)
    img = c["stream"].image
    streamrt.save(img, str(tmp_path / "x.pfm"))
    np.testing.assert_array_equal(read_pfm(tmp_path / "x.pfm"), img)
    with pytest.raises(ValueError):
        streamrt.save(np.zeros((4, 4)), str(tmp_path / "bad.png"))


def read_obj(path):
    """Vertices and triangles of an OBJ file of v and triangle f lines, read here."""
    vertices, triangles = [], []
    for line in pathlib.Path(path).read_text().splitlines():
        parts = line.split()
        if parts and parts[0] == "v":
            vertices.append([float(x) for x in parts[1:4]])
        elif parts and parts[0] == "f":
            triangles.append([int(p.split("/")[0]) - 1 for p in parts[1:4]])
    return np.array(vertices, np.float32), np.array(triangles, np.uint32)


def test_a_scene_built_from_arrays_renders_like_the_cfg_file():
    obj = ROOT / "scenes/meshes/icosphere.obj"
    head = ("image width=48 height=32 spp=2 depth=3\ncamera eye=0,1,5 look=0,0.5,0 fov=40\n"
            "light point pos=3,6,4\nplane color=0.4,0.4,0.4 checker=0.2,0.2,0.2\n")
    keys = "smooth=true color=0.9,0.45,0.2 refl=0.3 translate=0,1,0"
    with tempfile.TemporaryDirectory() as d:
        cfg = pathlib.Path(d) / "m.cfg"
        cfg.write_text(head + f"mesh file={obj} {keys}\n")
        want = streamrt.render(str(cfg)).image
    scene = streamrt.Scene()
    scene.add(head.rstrip("\n"))
    v, t = read_obj(obj)
    scene.mesh(v, t, smooth=True, color=(0.9, 0.45, 0.2), refl=0.3, translate=(0, 1, 0))
    assert "mesh file=memory:0 smooth=true color=0.9,0.45,0.2 refl=0.3 translate=0,1,0" in scene.text
    np.testing.assert_array_equal(streamrt.render(scene).image, want)
    # Statements from keywords, checked by the scene reader like any file.
    scene.statement("sphere", color=(0, 0, 1), translate=(2, 1, 0), scale=0.5)
    assert streamrt.render(scene).image.shape == (32, 48, 3)
    bad = streamrt.Scene()
    bad.statement("sphere", colour=(1, 0, 0))
    with pytest.raises(streamrt.SceneError) as e:
        streamrt.render(bad)
    assert (e.value.file, e.value.line, e.value.column) == ("<scene>", 1, 8)
    held = streamrt.Scene()
    held.mesh(v, t)
    held.add("mesh file=memory:3")
    with pytest.raises(streamrt.SceneError, match="no in-memory mesh 'memory:3' \\(there are 1\\)"):
        streamrt.render(held)
    with pytest.raises(streamrt.SceneError, match="cannot open mesh file"):  # text holds no meshes
        streamrt.render("image width=8 height=8\nmesh file=memory:0\n")
    with pytest.raises(ValueError, match="out of range"):
        streamrt.Scene().mesh(v, t + 10000)


def test_a_mesh_from_arrays_takes_vertex_colours():
    # One triangle filling the view, degree 0: every pixel is its hit's interpolated colour.
    v = np.array([[-9, -9, 0], [9, -9, 0], [0, 9, 0]], np.float32)
    t = np.array([[0, 1, 2]], np.uint32)
    head = "image width=16 height=12 spp=1 degree=0\ncamera eye=0,0,3 look=0,0,0"
    scene = streamrt.Scene()
    scene.add(head)
    scene.mesh(v, t, colors=np.full((3, 3), [0.25, 0.5, 0.125], np.float32), vertex_colors=True)
    image = streamrt.render(scene).image
    np.testing.assert_allclose(image.reshape(-1, 3), np.tile([0.25, 0.5, 0.125], (16 * 12, 1)), rtol=1e-5)
    rgb = streamrt.Scene()
    rgb.add(head)
    rgb.mesh(v, t, colors=np.eye(3, dtype=np.float32), vertex_colors=True)
    both = streamrt.compare(rgb)
    np.testing.assert_allclose(both["stream"].image.sum(axis=2), 1.0, rtol=1e-5)  # barycentric weights
    np.testing.assert_allclose(both["stream"].image, both["recursive"].image, rtol=1e-5, atol=1e-6)
    with pytest.raises(ValueError, match="colors: expected an array of shape"):
        streamrt.Scene().mesh(v, t, colors=np.zeros((2, 3), np.float32))
    with pytest.raises(ValueError, match="must be finite and >= 0"):
        streamrt.Scene().mesh(v, t, colors=np.full((3, 3), -1, np.float32))
    bare = streamrt.Scene()
    bare.add(head)
    bare.mesh(v, t, vertex_colors=True)
    with pytest.raises(streamrt.SceneError, match="in-memory mesh 'memory:0' was made without them"):
        streamrt.render(bare)


def test_memory_limit_refuses_a_mesh_before_reading_it_and_is_undone_after(tmp_path):
    # A 64 x 64 grid of quads (8,192 triangles) as OBJ text, named by the scene's line 3.
    n = 64
    lines = ["v %d %d 0" % (i, j) for j in range(n + 1) for i in range(n + 1)]
    for j in range(n):
        for i in range(n):
            a = j * (n + 1) + i + 1
            lines += ["f %d %d %d" % (a, a + 1, a + n + 2), "f %d %d %d" % (a, a + n + 2, a + n + 1)]
    (tmp_path / "grid.obj").write_text("\n".join(lines) + "\n")
    scene = tmp_path / "s.cfg"
    scene.write_text("image width=16 height=16 degree=0\ncamera eye=32,32,80 look=32,32,0 fov=60\n"
                     "mesh file=grid.obj color=1,0,0\n")
    # This process holds far more than 1 MiB already: the budget has no room, and the mesh's
    # text is the first thing counted.
    with pytest.raises(MemoryError) as e:
        streamrt.render(str(scene), memory_limit="1M")
    # (The mesh's path is shortened in the middle when long, as in every message.)
    assert str(e.value).startswith("%s:3:11: '" % scene)
    assert str(e.value).endswith("': its text would need about %.1f KiB, past the memory budget of 0 bytes "
                                 "(--memory-limit 1.0 MiB less what the process held before); --memory-limit raises it"
                                 % ((tmp_path / "grid.obj").stat().st_size / 1024))
    # The limit was for that call alone: the next one renders (the grid fills the view: red).
    img = streamrt.render(str(scene)).image
    np.testing.assert_array_equal(img[8, 8], [1, 0, 0])
    assert streamrt.render(str(scene), memory_limit=64 << 30).image[8, 8].tolist() == [1, 0, 0]
    with pytest.raises(ValueError, match="memory_limit: 'lots' is not a size"):
        streamrt.render(str(scene), memory_limit="lots")
    with pytest.raises(ValueError, match="memory_limit: expected a positive size"):
        streamrt.render(str(scene), memory_limit=0)
