#!/usr/bin/env python3
"""Checks that every engine folder includes only folders below it (docs/architecture.md,
"Folders and layers"), so the folders can be read in order and none depends on another in a
cycle. Prints each offending include as file:line and exits 1; exits 0 when the layering holds.

    python3 tests/architecture/check_layers.py [ENGINE_DIR]
"""
import pathlib
import re
import sys

# Lowest first. Folders on one line are peers: neither may include the other.
LAYERS = [
    ["simd"],
    ["core", "parallel"],
    ["image", "lights", "materials", "shapes"],
    ["accel"],
    ["mesh"],
    ["scene"],
    ["render"],
    ["kernels"],
    ["stream", "baseline"],
    ["driver"],
    ["distributed", "preview"],  # preview: streamrt serve (renders through driver/)
    ["cli", "modules"],
    ["python"],  # python -m streamrt runs the command (cli/command.cpp)
]
LEVEL = {folder: i for i, peers in enumerate(LAYERS) for folder in peers}
INCLUDE = re.compile(r'^\s*#\s*include\s+"([a-z_0-9]+)/[^"]+"')


def violations(engine: pathlib.Path):
    for path in sorted(engine.rglob("*")):
        if path.suffix not in (".h", ".cpp", ".inc"):
            continue
        folder = path.relative_to(engine).parts[0]
        if folder not in LEVEL:
            yield f"{path}: folder '{folder}' has no layer in tests/architecture/check_layers.py"
            continue
        for number, line in enumerate(path.read_text().splitlines(), 1):
            m = INCLUDE.match(line)
            if not m or m.group(1) == folder:
                continue
            target = m.group(1)
            if target not in LEVEL:
                yield f"{path}:{number}: includes '{target}/', a folder with no layer"
            elif LEVEL[target] >= LEVEL[folder]:
                kind = "a peer" if LEVEL[target] == LEVEL[folder] else "a layer above"
                yield f"{path}:{number}: {folder}/ includes {target}/ ({kind})"


def main() -> int:
    engine = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).parents[2] / "engine")
    found = list(violations(engine))
    for v in found:
        print(v)
    print(f"{len(found)} layering violation(s) in {engine}")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
