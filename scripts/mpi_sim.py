#!/usr/bin/python3
"""Discrete-event model of streamrt's MPI tile scheduling (engine/distributed/mpi_render.cpp),
replaying measured per-tile costs, to predict parallel efficiency beyond the ranks this
machine has (docs/distributed.md, "Scaling beyond this machine").

Input: the CSV that `streamrt --tile-costs FILE` writes (index,x0,y0,x1,y1,rays,seconds: each
tile's rays and its render time on one thread). The costs are turned into a cost per pixel
sample over the image and replayed at a target size and sample count: a target tile costs
the density at its position x 256 pixels x spp (a ray costs what it cost in the measured
render; the picture's layout scales with the image).

What is modelled, as the code does it:
- rank 0 hands out tiles from one row-major list; `dynamic`: a worker that returns a chunk
  gets the next chunk, of clamp(left / (2 N), j, 8 j) tiles; `static`: rank r gets list
  positions r, r + N, ..., in chunks of 4 j. A worker asks again only once its chunk is
  rendered and sent (no prefetch), so it idles for a round trip per chunk.
- rank 0's j threads render too, taking one tile at a time from the same list (static: from
  rank 0's positions); its main thread polls for messages every 200 us when none is waiting.
- a message costs latency + bytes / bandwidth; the results of a tile are 256 x 3 floats plus a
  64-byte record head; rank 0's incoming link is shared by every worker (served in turn).
- a rank's j threads take its chunk's tiles one at a time (oneTBB, grain 1).
Not modelled: memory-bandwidth contention inside a node, stragglers, the scene broadcast and
the image write (the same for every schedule, and measured separately).

usage: /usr/bin/python3 scripts/mpi_sim.py --costs costs.csv [--width 3840 --height 2160
           --spp 64 --source-spp 4 --jobs 16 --ranks 1,2,4,...,256 --network 25gbe]
       ... --validate "N:seconds,..." --cores 2  (compare with measured runs here)
       ... --plot docs/img/mpi_scaling.png --csv out.csv
"""
import argparse
import csv
import heapq
import math
import sys

TILE = 16
# Typical one-way small-message latency and bandwidth of MPI over common interconnects
# (orders of magnitude from the OSU micro-benchmarks' published results and vendor data
# sheets: TCP over Ethernet tens of microseconds, RDMA over InfiniBand about a microsecond).
NETWORKS = {
    "shm": (1e-6, 5e9, "shared memory, one node"),
    "10gbe": (50e-6, 1.1e9, "10 Gb Ethernet, TCP"),
    "25gbe": (25e-6, 2.8e9, "25 Gb Ethernet, TCP"),
    "100gbe": (15e-6, 11e9, "100 Gb Ethernet, TCP"),
    "ib-edr": (1.5e-6, 11.5e9, "InfiniBand EDR (100 Gb/s), RDMA"),
}
POLL = 200e-6          # rank 0's sleep between polls when no message waits
TILE_BYTES = TILE * TILE * 3 * 4 + 64


def read_costs(path, measure="rays"):
    """Tiles as (x0, y0, x1, y1, seconds). measure=rays: each tile's share of the total time
    is its share of the rays (deterministic: a loaded machine's hiccups, which the seconds
    of one tile carry and the model would scale up by the sample count, are left out);
    measure=seconds: the measured times as they are."""
    with open(path) as f:
        rows = list(csv.DictReader(f))
    total = sum(float(r["seconds"]) for r in rows)
    rays = sum(float(r["rays"]) for r in rows)
    cost = (lambda r: float(r["rays"]) / rays * total) if measure == "rays" else (lambda r: float(r["seconds"]))
    tiles = [(int(r["x0"]), int(r["y0"]), int(r["x1"]), int(r["y1"]), cost(r)) for r in rows]
    width = max(t[2] for t in tiles)
    height = max(t[3] for t in tiles)
    return tiles, width, height


def target_costs(tiles, src_w, src_h, src_spp, width, height, spp):
    """Cost of each target tile (row-major) from the measured cost per pixel sample."""
    nx_s = (src_w + TILE - 1) // TILE
    density = {}
    for x0, y0, x1, y1, sec in tiles:
        density[(x0 // TILE, y0 // TILE)] = sec / ((x1 - x0) * (y1 - y0) * src_spp)
    out = []
    for ty in range((height + TILE - 1) // TILE):
        for tx in range((width + TILE - 1) // TILE):
            w = min(width, (tx + 1) * TILE) - tx * TILE
            h = min(height, (ty + 1) * TILE) - ty * TILE
            cx = (tx * TILE + w / 2) / width * src_w
            cy = (ty * TILE + h / 2) / height * src_h
            key = (min(int(cx) // TILE, nx_s - 1), int(cy) // TILE)
            out.append(density.get(key, 0.0) * w * h * spp)
    return out


def run_threads(start, costs, jobs):
    """Makespan of tiles taken one at a time by `jobs` threads from `start`."""
    free = [start] * jobs
    heapq.heapify(free)
    for c in costs:
        t = heapq.heappop(free)
        heapq.heappush(free, t + c)
    return max(free)


def simulate_prefetch(costs, ranks, jobs, latency, bandwidth, speed=1.0):
    """Dynamic scheduling where a worker's threads take tiles one at a time from a local queue
    and the worker asks for its next chunk (sending the tiles finished so far) as soon as
    fewer than `jobs` tiles are left queued, so no thread waits for a round trip or for the
    slowest tile of a chunk. (A proposed design: the model's answer to the measured barrier.)"""
    costs = [c / speed for c in costs]
    n = len(costs)
    msg = lambda nbytes: latency + nbytes / bandwidth
    cursor = 0
    queue = {r: [] for r in range(ranks)}
    asking = {r: False for r in range(ranks)}
    finished = {r: 0 for r in range(ranks)}
    events = []
    link_free = 0.0
    master_free = 0.0
    end = 0.0

    def chunk():
        return max(jobs, min(8 * jobs, (n - cursor) // (2 * ranks)))

    def ask(r, t):
        nonlocal link_free
        asking[r] = True
        arrive = max(t + latency, link_free) + finished[r] * TILE_BYTES / bandwidth
        link_free = arrive
        finished[r] = 0
        heapq.heappush(events, (arrive, 1, "request", r))

    for r in range(1, ranks):
        ask(r, 0.0)
    for r in range(ranks):
        for k in range(jobs):
            heapq.heappush(events, (0.0, 0, "thread", r))
    while events:
        t, _, kind, r = heapq.heappop(events)
        if kind == "request":
            start = max(t, master_free)
            if start == t:
                start += POLL / 2
            master_free = start + 2e-6
            k = chunk()
            tiles = list(range(cursor, min(n, cursor + k)))
            cursor += len(tiles)
            heapq.heappush(events, (master_free + msg(4 * len(tiles)), 1, "reply", (r, tiles)))
        elif kind == "reply":
            r, tiles = r
            asking[r] = False
            queue[r].extend(tiles)
            if tiles:
                # Wake the threads that found the queue empty.
                for _ in range(len(tiles)):
                    heapq.heappush(events, (t, 0, "wake", r))
            else:
                asking[r] = None  # no more work for this rank
                end = max(end, t + msg(finished[r] * TILE_BYTES))
        elif kind in ("thread", "wake"):
            if kind == "wake" and r in idle and idle[r] > 0:
                idle[r] -= 1
            elif kind == "wake":
                continue
            if r == 0:
                if cursor < n:
                    i = cursor
                    cursor += 1
                    heapq.heappush(events, (t + costs[i], 0, "thread", 0))
                    end = max(end, t + costs[i])
                continue
            if kind == "thread" and t > 0:
                finished[r] += 1
            if queue[r]:
                i = queue[r].pop(0)
                heapq.heappush(events, (t + costs[i], 0, "thread", r))
                end = max(end, t + costs[i])
                if len(queue[r]) < jobs and asking[r] is False:
                    ask(r, t)
            else:
                idle[r] = idle.get(r, 0) + 1
                if asking[r] is False:
                    ask(r, t)
    return end


idle = {}


def simulate(costs, ranks, jobs, schedule, latency, bandwidth, speed=1.0):
    """Wall time of one render on `ranks` ranks of `jobs` threads (speed < 1: shared cores)."""
    if schedule == "prefetch" and ranks > 1:
        idle.clear()
        return simulate_prefetch(costs, ranks, jobs, latency, bandwidth, speed)
    costs = [c / speed for c in costs]
    n = len(costs)
    if ranks == 1:
        return run_threads(0.0, costs, jobs)
    msg = lambda nbytes: latency + nbytes / bandwidth
    cursor = 0                       # dynamic: next list position
    own = {r: list(range(r, n, ranks)) for r in range(ranks)}  # static positions
    own_next = {r: 0 for r in range(ranks)}

    def take(rank, k):
        nonlocal cursor
        if schedule == "dynamic":
            out = list(range(cursor, min(n, cursor + k)))
            cursor += len(out)
            return out
        p = own_next[rank]
        out = own[rank][p:p + k]
        own_next[rank] = p + len(out)
        return out

    def chunk():
        if schedule == "static":
            return 4 * jobs
        left = n - cursor
        return max(jobs, min(8 * jobs, left // (2 * ranks)))

    # Rank 0's threads: one tile at a time, interleaved with the workers' requests in time.
    events = []  # (time, kind, rank, payload)
    for t in range(jobs):
        heapq.heappush(events, (0.0, 0, "local", t))
    for r in range(1, ranks):
        heapq.heappush(events, (msg(8), 1, "request", r))  # the first ask carries no tiles
    link_free = 0.0   # rank 0's incoming link
    master_free = 0.0
    end = 0.0
    while events:
        t, _, kind, who = heapq.heappop(events)
        if kind == "local":
            tiles = take(0, 1)
            if not tiles:
                end = max(end, t)
                continue
            heapq.heappush(events, (t + costs[tiles[0]], 0, "local", who))
        elif kind == "request":
            # Polling: a message that finds rank 0 idle waits half a poll on average.
            start = max(t, master_free)
            if start == t:
                start += POLL / 2
            tiles = take(who, chunk())
            master_free = start + 2e-6
            if not tiles:
                end = max(end, master_free)
                continue
            got = master_free + msg(4 * len(tiles))
            done = run_threads(got, [costs[i] for i in tiles], jobs)
            heapq.heappush(events, (done, 1, "send", (who, len(tiles))))
        elif kind == "send":
            # The results share rank 0's incoming link, in the order they are sent.
            who, count = who
            arrive = max(t + latency, link_free) + count * TILE_BYTES / bandwidth
            link_free = arrive
            heapq.heappush(events, (arrive, 1, "request", who))
            end = max(end, arrive)
    return end


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--costs", required=True)
    ap.add_argument("--source-spp", type=int, required=True, help="spp of the render that wrote --costs")
    ap.add_argument("--measure", choices=("rays", "seconds"), default="rays",
                    help="a tile's cost: its share of the rays (default) or its own measured seconds")
    ap.add_argument("--width", type=int)
    ap.add_argument("--height", type=int)
    ap.add_argument("--spp", type=int)
    ap.add_argument("--jobs", type=int, default=16, help="threads per rank")
    ap.add_argument("--ranks", default="1,2,4,8,16,32,64,128,256")
    ap.add_argument("--network", default="25gbe", help=",".join(NETWORKS))
    ap.add_argument("--validate", help="measured wall seconds here, 'N:s,N:s,...' (same size as --costs)")
    ap.add_argument("--cores", type=int, default=2, help="cores of this machine (for --validate)")
    ap.add_argument("--plot")
    ap.add_argument("--csv")
    a = ap.parse_args()
    tiles, src_w, src_h = read_costs(a.costs, a.measure)
    if a.validate:
        costs = target_costs(tiles, src_w, src_h, a.source_spp, src_w, src_h, a.source_spp)
        lat, bw, _ = NETWORKS["shm"]
        print("ranks  schedule  measured s  model s  model/measured")
        for item in a.validate.split(","):
            n, sec = item.split(":")
            n, sec = int(n), float(sec)
            speed = min(1.0, a.cores / (n * a.jobs))
            model = simulate(costs, n, a.jobs, "dynamic", lat, bw, speed)
            print(f"{n:5d}  dynamic   {sec:10.3f}  {model:7.3f}  {model / sec:6.2f}")
        return 0
    costs = target_costs(tiles, src_w, src_h, a.source_spp, a.width, a.height, a.spp)
    ranks = [int(r) for r in a.ranks.split(",")]
    nets = a.network.split(",")
    rows = []
    t1 = simulate(costs, 1, a.jobs, "dynamic", 0, 1)
    print(f"{len(costs)} tiles, {sum(costs):.1f} s of one thread; one rank of {a.jobs} threads: {t1:.2f} s")
    print("network  schedule  " + "  ".join(f"{r:>6d}" for r in ranks) + "   (parallel efficiency)")
    for net in nets:
        lat, bw, _ = NETWORKS[net]
        for schedule in ("dynamic", "static", "prefetch"):
            effs = []
            for r in ranks:
                tn = simulate(costs, r, a.jobs, schedule, lat, bw)
                effs.append(t1 / (r * tn))
                rows.append({"network": net, "schedule": schedule, "ranks": r, "seconds": tn, "efficiency": t1 / (r * tn)})
            print(f"{net:8s} {schedule:8s}  " + "  ".join(f"{e * 100:5.1f}%" for e in effs))
    if a.csv:
        with open(a.csv, "w", newline="") as f:
            w = csv.DictWriter(f, fieldnames=list(rows[0]))
            w.writeheader()
            w.writerows(rows)
    if a.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(6, 3.6))
        colors = {"dynamic": "tab:blue", "static": "tab:red", "prefetch": "tab:green"}
        styles = ["-", "--", ":", "-."]
        for k, net in enumerate(nets):
            for schedule in ("dynamic", "static", "prefetch"):
                pts = [(r["ranks"], r["efficiency"]) for r in rows if r["network"] == net and r["schedule"] == schedule]
                ax.plot([p[0] for p in pts], [p[1] * 100 for p in pts], styles[k % 4], color=colors[schedule],
                        marker="o", ms=3, label=f"{schedule}, {NETWORKS[net][2]}")
        ax.set_xscale("log", base=2)
        ax.set_xlabel(f"ranks ({a.jobs} threads each)")
        ax.set_ylabel("predicted parallel efficiency, %")
        ax.set_ylim(0, 105)
        ax.axhline(85, color="grey", lw=0.5)
        ax.set_title(f"{a.width}x{a.height}, {a.spp} spp, replayed tile costs", fontsize=9)
        ax.legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(a.plot, dpi=80)
    return 0


if __name__ == "__main__":
    sys.exit(main())
