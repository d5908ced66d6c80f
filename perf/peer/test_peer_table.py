"""scripts/peer_bench.py --table on a hand-written log of known values (peer_runs_fixture.jsonl
beside this file): one table per benchmark, a row per scene with its runs, days, loads and
ISAs, and per ratio the lowest value (the headline) with the range over the runs. Run by ctest
("perf: peer_bench.py --table aggregates a log of runs")."""
import pathlib
import subprocess
import sys

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parents[1]
FIXTURE = HERE / "peer_runs_fixture.jsonl"


def table(*args):
    r = subprocess.run([sys.executable, str(ROOT / "scripts" / "peer_bench.py"), "--table", "--log", str(FIXTURE),
                        *args], capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    return r.stdout.splitlines()


def rows(lines):
    return [ln for ln in lines if ln.startswith("| ") and not ln.startswith("| scene")]


# Proven against: the headline taken as the median (18.50x read 20.00x), days counted by
# timestamp instead of by date (2 read 3), and the first draft's filter that kept only metrics
# ending in "ratio" (every POV-Ray ratio, "ratio default", left out).
def test_rows_worked_by_hand():
    lines = table()
    assert rows(lines) == [
        # bunny: "ratio default" 20.0, 18.5, 22.25 over two days (lowest 18.5); "ratio nopruning" in
        # two of the three runs, 17.5 and 17.0; loads 1.5, 2.5, 0.5; two ISAs
        "| bunny | 3 | 2 (2026-12-01, 2026-12-02) | 0.5 - 2.5 | avx2, avx512 | **18.50x** (18.50 - 22.25) "
        "| **17.00x** (17.00 - 17.50, n=2) |",
        # sphere1m: primary 1.25, 1.5; shadow 1.4, 1.6 (Mrays/s are not ratios: no column)
        "| sphere1m | 2 | 2 (2026-12-02, 2026-12-03) | 0.8 - 1.8 | avx512 | **1.25x** (1.25 - 1.50) "
        "| **1.40x** (1.40 - 1.60) |",
    ]
    headers = [ln for ln in lines if ln.startswith("| scene")]
    assert headers == ["| scene | runs | days | load (1 min) | ISA | ratio default | ratio nopruning |",
                       "| scene | runs | days | load (1 min) | ISA | primary ratio | shadow ratio |"]


def test_metric_filter():
    lines = table("--metrics", "shadow ratio")
    assert rows(lines) == ["| sphere1m | 2 | 2 (2026-12-02, 2026-12-03) | 0.8 - 1.8 | avx512 | **1.40x** (1.40 - 1.60) |"]


def test_entry_count_line():
    assert any(ln.startswith("5 entries from ") for ln in table())


# Proven against: --since compared with ">" (the run at exactly 2026-12-01T11:00Z dropped:
# 2 read 1) and --scenes ignored by --table (the sphere1m row kept).
def test_since_and_scenes():
    # From 11:00 on the first day: bunny's 18.5 and 22.25 (17.0 alone for nopruning).
    assert rows(table("--since", "2026-12-01T11:00Z", "--scenes", "bunny")) == [
        "| bunny | 2 | 2 (2026-12-01, 2026-12-02) | 0.5 - 2.5 | avx2, avx512 | **18.50x** (18.50 - 22.25) "
        "| **17.00x** (17.00 - 17.00, n=1) |"]
    # A day alone, as a date: the last sphere1m run.
    assert rows(table("--since", "2026-12-03")) == [
        "| sphere1m | 1 | 1 (2026-12-03) | 1.8 - 1.8 | avx512 | **1.50x** (1.50 - 1.50) | **1.60x** (1.60 - 1.60) |"]


# Proven against: --isa ignored (the avx512 runs kept: bunny 3 runs instead of 2, a sphere1m row).
def test_isa():
    # bunny's two avx2 runs of 2026-12-01: default 20.0 and 18.5, nopruning 17.5 and 17.0,
    # loads 1.5 and 2.5; no sphere1m (avx512 only).
    assert rows(table("--isa", "avx2")) == [
        "| bunny | 2 | 1 (2026-12-01) | 1.5 - 2.5 | avx2 | **18.50x** (18.50 - 20.00) | **17.00x** (17.00 - 17.50) |"]
