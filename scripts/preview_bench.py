#!/usr/bin/env python3
"""streamrt serve's interactive figures (docs/performance.md, "Live preview"): frames per second
while the camera moves (each move posted with moving=1, the next posted once its picture is out:
the page's own rhythm at its fastest), and the time from a save of the scene to the first
updated picture. A benchmark, not a test: it prints figures and checks nothing.

    /usr/bin/python3 scripts/preview_bench.py [--streamrt build/engine/streamrt] [-j 2] [--size WxH] SCENE...

--size WxH serves a copy of each scene with its `image` statement's width and height replaced
(written beside the scene, so that its relative paths hold, and removed afterwards).
"""
import argparse
import http.client
import json
import math
import os
import pathlib
import re
import shutil
import signal
import statistics
import subprocess
import tempfile
import time


def request(port, method, path, body=None):
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=60)
    c.request(method, path, body=body)
    r = c.getresponse()
    data = r.read()
    c.close()
    return r.status, data


def status(port):
    return json.loads(request(port, "GET", "/status")[1])


def wait(port, done):
    while True:
        s = status(port)
        if done(s):
            return s
        time.sleep(0.001)


def bench(streamrt, scene, jobs, moves, saves):
    work = pathlib.Path(tempfile.mkdtemp(prefix="streamrt_preview_bench_"))
    # A copy beside the original's files would need its includes; the scene is saved in place
    # with its own bytes (the watch sees the new modification time).
    server = subprocess.Popen([streamrt, "serve", scene, "--port", "0", "-j", str(jobs)], stdout=subprocess.PIPE,
                              text=True)
    try:
        url = server.stdout.readline().split()[-1]
        port = int(url.rsplit(":", 1)[1].strip("/"))
        s = wait(port, lambda t: t["pass"] == "idle")
        cam = s["camera"]
        eye, look = cam["eye"], cam["look"]
        off = [eye[i] - look[i] for i in range(3)]
        radius = math.hypot(off[0], off[2])
        frame = s["frame"]
        sizes = None
        start = time.perf_counter()
        for k in range(moves):
            a = math.atan2(off[0], off[2]) + 0.01 * (k + 1)
            e = [look[0] + radius * math.sin(a), eye[1], look[2] + radius * math.cos(a)]
            body = f"eye={e[0]:.6g},{e[1]:.6g},{e[2]:.6g}&moving=1"
            request(port, "POST", "/camera", body)
            s = wait(port, lambda t: t["frame"] > frame)
            frame = s["frame"]
            sizes = s["picture"]["width"], s["picture"]["height"]
        fps = moves / (time.perf_counter() - start)
        # Saves: the same bytes written again (a new modification time), timed to the first
        # new picture (the quick pass).
        path = pathlib.Path(scene)
        text = path.read_bytes()
        latencies = []
        for _ in range(saves):
            s = wait(port, lambda t: t["pass"] in ("idle", "quick"))
            frame = s["frame"]
            time.sleep(0.2)
            t0 = time.perf_counter()
            path.write_bytes(text)
            wait(port, lambda t: t["frame"] > frame)
            latencies.append(time.perf_counter() - t0)
        return fps, sizes, latencies
    finally:
        server.send_signal(signal.SIGINT)
        server.wait(timeout=60)
        shutil.rmtree(work, ignore_errors=True)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scenes", nargs="+")
    ap.add_argument("--streamrt", default="build/engine/streamrt")
    ap.add_argument("-j", "--jobs", type=int, default=2)
    ap.add_argument("--moves", type=int, default=100)
    ap.add_argument("--saves", type=int, default=10)
    ap.add_argument("--size", help="WxH: the scenes served at this width and height")
    a = ap.parse_args()
    print("| scene | moving: picture | frames/s | save to picture, median (max) |")
    print("|---|---|---|---|")
    for scene in a.scenes:
        served, label = scene, scene
        if a.size:
            w, h = a.size.lower().split("x")
            text = pathlib.Path(scene).read_text()
            sized = re.sub(r"^(image\b.*?)\bwidth=\d+", rf"\g<1>width={int(w)}", text, count=1, flags=re.M)
            sized = re.sub(r"^(image\b.*?)\bheight=\d+", rf"\g<1>height={int(h)}", sized, count=1, flags=re.M)
            assert sized != text or f"width={int(w)}" in text, f"{scene}: no image width=/height= to replace"
            served = os.path.join(os.path.dirname(scene), f".preview_bench_{os.getpid()}_{os.path.basename(scene)}")
            pathlib.Path(served).write_text(sized)
            label = f"{scene} at {int(w)}x{int(h)}"
        try:
            fps, size, lat = bench(a.streamrt, served, a.jobs, a.moves, a.saves)
        finally:
            if served != scene:
                os.remove(served)
        print(f"| `{label}` | {size[0]}x{size[1]}, 1 spp | {fps:.0f} | {statistics.median(lat) * 1000:.0f} ms "
              f"({max(lat) * 1000:.0f} ms) |")


if __name__ == "__main__":
    main()
