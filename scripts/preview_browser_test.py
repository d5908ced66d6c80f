#!/usr/bin/env python3
"""streamrt serve in a real browser (docs/preview.md): Debian's headless Chromium opens the
page, and the picture it shows must be the command line's render of the same scene, pixel for
pixel; a scripted drag (the page's ?drag= test hook) orbits the camera by the amount the
page's orbit math gives, and the page then shows the command line's render with that camera; a save re-renders and the page shows the new frame; a broken save shows its
file:line:col error on the page. Skips (exit 77) where chromium or the HTTP server is missing.

    scripts/preview_browser_test.py --streamrt build/engine/streamrt [--shot build/preview.png]

Chromium runs without the DevTools protocol: --dump-dom and --screenshot with a virtual time
budget, which lets the page's polling run until the budget is spent."""
import argparse
import http.client
import json
import math
import os
import pathlib
import shutil
import signal
import subprocess
import sys
import tempfile
import time

SCALE = float(os.environ.get("STREAMRT_TEST_TIMEOUT_SCALE", "1"))
SCENE = """image width=96 height=64 spp=2 depth=3 degree=5 output={out}
background {background}
camera eye=0,1.6,6 look=0,0.8,0 up=0,1,0 fov=40
light point pos=-4,7,6 color=0.8,0.8,0.8
plane color=0.95,0.85,0.1 checker=0.85,0.1,0.05 cell=1 ambi=1 diff=0.9
sphere color=0.9,0.9,0.9 refl=0.6 scale=1 translate=-0.9,1,-1.5
"""


def chromium():
    for name in ("chromium", "chromium-browser", "google-chrome"):
        if shutil.which(name):
            return shutil.which(name)
    return None


def status(port):
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=30)
    c.request("GET", "/status")
    r = c.getresponse()
    body = r.read()
    c.close()
    return json.loads(body)


def wait_for(port, done, what):
    give_up = time.monotonic() + 60 * SCALE
    s = None
    while time.monotonic() < give_up:
        s = status(port)
        if done(s):
            return s
        time.sleep(0.02)
    raise SystemExit(f"FAIL: the server never reached {what}; last status {s}")


def browser(exe, profile, url, *args, budget=4000):
    cmd = [exe, "--headless=new", "--no-sandbox", "--disable-gpu", "--no-first-run", "--disable-extensions",
           "--force-device-scale-factor=1", "--hide-scrollbars", f"--user-data-dir={profile}",
           f"--virtual-time-budget={budget}", *args, url]
    return subprocess.run(cmd, capture_output=True, text=True, timeout=120 * SCALE)


def find_picture(shot, picture):
    """The offset where `picture` (H x W x 3, 0-255) appears exactly in `shot`, or None."""
    import numpy as np
    h, w = picture.shape[:2]
    first = picture[0, 0]
    ys, xs = np.nonzero(np.all(shot[: shot.shape[0] - h + 1, : shot.shape[1] - w + 1] == first, axis=2))
    for y, x in zip(ys, xs):
        if np.array_equal(shot[y:y + h, x:x + w], picture):
            return int(x), int(y)
    return None


def png_bytes(path):
    import matplotlib.image as mpimg
    import numpy as np
    a = mpimg.imread(path)
    return np.rint(a[..., :3] * 255).astype(np.uint8)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--streamrt", required=True)
    ap.add_argument("--shot", help="keep the page's screenshot here")
    a = ap.parse_args()
    exe = chromium()
    if not exe:
        print("SKIP: no chromium")
        return 77
    work = pathlib.Path(tempfile.mkdtemp(prefix="streamrt_preview_browser_"))
    scene = work / "scene.cfg"
    scene.write_text(SCENE.format(out=work / "out.png", background="0.35,0.55,0.85"))
    server = subprocess.Popen([a.streamrt, "serve", str(scene), "--port", "0", "-j", "2"], stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True)
    try:
        first = server.stdout.readline()
        if not first:  # it exited before serving
            err = server.stderr.read()
            if "no HTTP server" in err:
                print("SKIP: streamrt has no HTTP server")
                return 77
            raise SystemExit("FAIL: serve did not start: " + err)
        assert first.startswith("streamrt serve: http://127.0.0.1:"), first
        url = first.split()[-1]
        port = int(url.rsplit(":", 1)[1].strip("/"))
        s = wait_for(port, lambda s: s["pass"] == "idle", "the full pass")

        # The picture on the page is the command line's.
        cli = work / "cli.png"
        subprocess.run([a.streamrt, str(scene), "-q", "-o", str(cli)], check=True, timeout=120 * SCALE)
        shot = work / "shot.png"
        r = browser(exe, work / "profile1", url, f"--screenshot={shot}", "--window-size=400,300")
        assert shot.exists(), r.stderr[-2000:]
        where = find_picture(png_bytes(shot), png_bytes(cli))
        assert where is not None, "the command line's picture is not on the page's screenshot"
        print(f"ok: the page shows the CLI's picture, pixel for pixel, at {where}")
        if a.shot:
            shutil.copyfile(shot, a.shot)

        # A scripted drag: ?drag=DX,0 makes the page dispatch mousedown, mousemoves and mouseup on
        # the picture once it is shown, so its own handlers and orbit code move the camera.
        # A drag of DX pixels sideways turns the eye about the up axis through the look point by
        # -DX * 0.01 radians: the scene's eye - look = (0, 0.8, 6) becomes (6 sin t, 0.8, 6 cos t).
        dx = 60
        shot_drag = work / "drag.png"
        r = browser(exe, work / "profile_drag", url + f"?drag={dx},0", f"--screenshot={shot_drag}",
                    "--window-size=400,300", budget=20000)
        assert shot_drag.exists(), r.stderr[-2000:]
        cam = status(port)["camera"]
        t = -dx * 0.01
        want = [6 * math.sin(t), 0.8 + 0.8, 6 * math.cos(t)]
        assert cam["look"] == [0, 0.8, 0] and cam["up"] == [0, 1, 0] and cam["fov"] == 40, cam
        assert all(abs(g - w) < 1e-4 for g, w in zip(cam["eye"], want)), \
            f"the drag's eye is {cam['eye']}, the orbit math gives {want} (scene's: [0, 1.6, 6])"
        print(f"ok: a scripted drag of {dx},0 pixels moved the eye to {cam['eye']} (orbit math: {want})")
        sd = wait_for(port, lambda t: t["pass"] == "idle" and t["frame"] > s["frame"], "the dragged camera's full pass")
        dragged = png_bytes(shot_drag)
        assert find_picture(dragged, png_bytes(cli)) is None, "after the drag the page still shows the undragged picture"
        moved_scene = work / "moved.cfg"
        moved_scene.write_text("\n".join(sd["camera_statement"] if line.startswith("camera ") else line
                                         for line in scene.read_text().splitlines()) + "\n")
        cli_moved = work / "cli_moved.png"
        subprocess.run([a.streamrt, str(moved_scene), "-q", "-o", str(cli_moved)], check=True, timeout=120 * SCALE)
        where_moved = find_picture(dragged, png_bytes(cli_moved))
        assert where_moved is not None, \
            f"after the drag the page does not show the CLI's render with {sd['camera_statement']!r}"
        print(f"ok: after the drag the page shows the CLI's render with {sd['camera_statement']!r}, pixel for pixel")
        s = sd

        # A save: a new frame, which the page loads.
        scene.write_text(SCENE.format(out=work / "out.png", background="0.9,0.2,0.2"))
        s2 = wait_for(port, lambda t: t["pass"] == "idle" and t["frame"] > s["frame"], "a new frame after the save")
        dom = browser(exe, work / "profile2", url, "--dump-dom").stdout
        assert f'data-frame="{s2["frame"]}"' in dom, dom[-2000:]
        print(f"ok: after the save the page shows frame {s2['frame']}")

        # A broken save: the error with its place on the page.
        scene.write_text(SCENE.format(out=work / "out.png", background="0.9,0.2,0.2") + "sphere radius=oops\n")
        s3 = wait_for(port, lambda t: t["error"] != "", "the broken save's error")
        assert "scene.cfg:7:" in s3["error"], s3["error"]
        dom = browser(exe, work / "profile3", url, "--dump-dom").stdout
        assert "scene.cfg:7:" in dom, dom[-2000:]
        print("ok: the broken save's error is on the page:", s3["error"])
    finally:
        server.send_signal(signal.SIGINT)
        try:
            code = server.wait(timeout=30 * SCALE)
        except subprocess.TimeoutExpired:
            server.kill()
            raise SystemExit("FAIL: the server did not stop on SIGINT")
        shutil.rmtree(work, ignore_errors=True)
    assert code == 0, f"serve exited {code} on SIGINT"
    print("ok: SIGINT stopped the server, exit status 0")
    return 0


if __name__ == "__main__":
    sys.exit(main())
