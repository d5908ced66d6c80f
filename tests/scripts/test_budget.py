"""scripts/budget.sh, the time budget CI runs the sanitizer suite under (.ci/run): a check
that does not finish within its budget fails (exit 1, one line naming it), one that finishes
keeps its own exit status. Run by ctest with the other script tests (scripts_generated_meshes)."""
import os
import subprocess
import time

BUDGET = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), "scripts",
                      "budget.sh")


def run(*args):
    start = time.monotonic()
    r = subprocess.run([BUDGET, *args], capture_output=True, text=True, timeout=60)
    return r, time.monotonic() - start


# Proven against: budget.sh exiting with timeout's 124 as .ci/run once read it (a pass).
def test_a_check_that_runs_out_of_time_fails():
    r, seconds = run("1", "the slow check", "sleep", "30")
    assert r.returncode == 1
    assert r.stderr == ("budget.sh: the slow check did not finish within its 1 budget: FAILED "
                        "(what it did not reach was not checked)\n")
    assert seconds < 20  # stopped at the budget, not waited out


def test_a_check_that_finishes_keeps_its_status():
    r, _ = run("30", "quick", "true")
    assert (r.returncode, r.stderr) == (0, "")
    r, _ = run("30", "failing", "sh", "-c", "echo report >&2; exit 3")
    assert (r.returncode, r.stderr) == (3, "report\n")


def test_the_whole_process_group_is_stopped():
    # A child of the command (as ctest is of sanitize.sh) must not outlive the budget.
    r, seconds = run("1", "nested", "sh", "-c", "sleep 30 & wait")
    assert r.returncode == 1
    assert seconds < 20
