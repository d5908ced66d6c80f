"""The README's short examples, run as written (ctest readme_commands): every command of the
"Using it" block that starts with build/engine/streamrt (the others fetch data, take minutes
or need other tools: the README says so on their line), and the "From Python" block; and every
build/engine/streamrt command of a shell block in docs/*.md that names no placeholder (an
upper-case word such as SCENE or MESH). Each must exit 0 and leave nothing new in the
repository's root folder and no tracked file changed (pictures go to build/)."""
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


def doc_commands():
    """The docs' build/engine/streamrt lines in ```sh blocks, without placeholders."""
    lines = []
    for md in sorted((ROOT / "docs").glob("*.md")):
        for m in re.finditer(r"```(?:sh|bash)\n(.*?)```", md.read_text(), re.S):
            for line in m.group(1).splitlines():
                if line.startswith("build/engine/streamrt ") and not re.search(r"\b[A-Z]{3,}\b", line.split("#")[0]):
                    lines.append(line)
    return lines


DOC_COMMANDS = doc_commands()


def tracked_changes():
    r = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no"], cwd=ROOT, capture_output=True,
                       text=True)
    return r.stdout if r.returncode == 0 else ""


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


def test_the_docs_have_their_commands():
    assert len(DOC_COMMANDS) >= 3  # distributed.md's tile costs, global-illumination.md's two renders


@pytest.mark.parametrize("line", DOC_COMMANDS)
def test_docs_command_runs_as_written(line):
    args = shlex.split(line, comments=True)
    args[0] = STREAMRT
    (ROOT / "build").mkdir(exist_ok=True)
    before, tracked = root_files(), tracked_changes()
    r = subprocess.run(args, cwd=ROOT, capture_output=True, text=True, timeout=300 * SCALE)
    assert r.returncode == 0, r.stderr
    assert root_files() - before == set(), "wrote into the repository's root"
    assert tracked_changes() == tracked, "changed a tracked file"


def test_readme_python_block_runs_as_written():
    code = block("## From Python", "python")
    before = root_files()
    env = dict(os.environ)
    r = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, env=env,
                       timeout=300 * SCALE)
    assert r.returncode == 0, r.stderr
    assert root_files() - before == set(), "wrote into the repository's root"
