"""The README's short examples, run as written (ctest readme_commands): every command of the
"Using it" block that starts with build/engine/streamrt (the others fetch data, take minutes
or need other tools: the README says so on their line), and the "From Python" block. Each must
exit 0 and leave nothing new in the repository's root folder (pictures go to build/)."""
import os
import pathlib
import re
import shlex
import subprocess
import sys

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
STREAMRT = os.environ.get("STREAMRT_BINARY", str(ROOT / "build/engine/streamrt"))
SCALE = float(os.environ.get("STREAMRT_TEST_TIMEOUT_SCALE", "1"))


def block(section, language):
    """The first ```language block after the README's heading `section`."""
    text = (ROOT / "README.md").read_text()
    start = text.index("\n" + section + "\n")
    m = re.compile(r"```" + language + r"\n(.*?)```", re.S).search(text, start)
    assert m, f"no ```{language} block under {section}"
    return m.group(1)


COMMANDS = [line for line in block("## Using it", "sh").splitlines() if line.startswith("build/engine/streamrt ")]


def root_files():
    return set(os.listdir(ROOT))


def test_the_block_has_its_commands():
    assert len(COMMANDS) >= 13  # as many as the block holds today


@pytest.mark.parametrize("line", COMMANDS)
def test_readme_command_runs_as_written(line):
    args = shlex.split(line, comments=True)
    args[0] = STREAMRT
    (ROOT / "build").mkdir(exist_ok=True)  # where the README's pictures go
    before = root_files()
    r = subprocess.run(args, cwd=ROOT, capture_output=True, text=True, timeout=300 * SCALE)
    assert r.returncode == 0, r.stderr
    assert root_files() - before == set(), "wrote into the repository's root"


def test_readme_python_block_runs_as_written():
    code = block("## From Python", "python")
    before = root_files()
    env = dict(os.environ)
    r = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, env=env,
                       timeout=300 * SCALE)
    assert r.returncode == 0, r.stderr
    assert root_files() - before == set(), "wrote into the repository's root"
