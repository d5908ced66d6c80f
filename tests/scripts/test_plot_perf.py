"""scripts/plot_perf.py: a run with nothing to plot fails, and the plots go to build/perf/img/
unless asked (--out docs/img), so a quick run never rewrites the pictures the docs show. Run
by ctest with the other script tests (scripts_generated_meshes)."""
import os
import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
PLOT = ROOT / "scripts" / "plot_perf.py"


def run(*args):
    return subprocess.run([sys.executable, str(PLOT), *map(str, args)], capture_output=True, text=True, timeout=120)


# Proven against: plot_perf.py's old "return 0" after "nothing to plot" (a pass for a chain of
# perf_suite.py && plot_perf.py that made no picture).
def test_nothing_to_plot_fails(tmp_path):
    missing = tmp_path / "missing"
    r = run("--results", missing, "--errors", missing, "--kernels", missing, "--out", tmp_path / "img")
    assert r.returncode == 1
    assert "nothing to plot" in r.stderr
    assert list((tmp_path / "img").iterdir()) == []


# Proven against: the old default --img docs/img (the plot landed beside the docs' pictures).
def test_plots_go_to_build_unless_asked(tmp_path):
    # One scene of the error-against-time CSV, under a name no tracked picture has.
    scene = "plot_perf_test_%d" % os.getpid()
    errors = tmp_path / "errors.csv"
    errors.write_text("scene,engine,sampler,spp,seconds,rmse,psnr,relmse\n"
                      f"{scene},stream,stratified,1,0.1,0.05,26,0.1\n"
                      f"{scene},stream,stratified,4,0.4,0.02,34,0.04\n")
    missing = tmp_path / "missing"
    r = run("--results", missing, "--errors", errors, "--kernels", missing)
    want = ROOT / "build" / "perf" / "img" / f"evt_{scene}.png"
    try:
        assert r.returncode == 0, r.stderr
        assert r.stdout.splitlines() == [f"plot: {want}"]
        assert want.exists()
        assert not (ROOT / "docs" / "img" / f"evt_{scene}.png").exists()
    finally:
        want.unlink(missing_ok=True)
        (ROOT / "docs" / "img" / f"evt_{scene}.png").unlink(missing_ok=True)
    asked = tmp_path / "asked"
    r = run("--results", missing, "--errors", errors, "--kernels", missing, "--out", asked)
    assert r.returncode == 0, r.stderr
    assert (asked / f"evt_{scene}.png").exists()
