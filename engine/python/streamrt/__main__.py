"""python -m streamrt SCENE.cfg [options]: the streamrt command line (README "Using it"),
run in this process by the extension (engine/cli/command.cpp), with its exit status."""
import sys

from ._native import run_command

sys.exit(run_command(sys.argv[1:]))
