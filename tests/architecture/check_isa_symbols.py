#!/usr/bin/env python3
"""Checks the kernel contract for instruction sets (docs/architecture.md, "Kernels and
instruction sets"): no code compiled with one level's flags can be picked by the linker for
callers built with other flags.

Reads the engine archive (the objects exactly as the linker sees them) with `nm` (no -C) and
groups its members by the flags they were built with: kernels/isa_<level>.cpp and
isa_<level>_accel.cpp form group <level>, every other member the baseline group. Fails when

  1. a global code symbol (nm types T, W, i: text, weak, inline/COMDAT functions) defined by a
     member of one level's group is also defined by a member of another group (another level
     or the baseline): the linker would keep one copy for every caller;
  2. a symbol of the project's own code (mangled name in namespace streamrt) defined by a
     level's member is not inside that level's namespace (streamrt::...::isa_<level>), other
     than the level's entry points (streamrt::isa_kernels::<level>*): the contract is that
     every function the kernels compile lives in the per-ISA namespace (simd/isa_namespace.h),
     so a helper left outside it is named even while the optimiser happens to inline it;
  3. a shared data symbol is not on the list below. Data symbols carry no instructions, and
     the bytes of a constant do not depend on the -m flags, so sharing one is harmless; each
     allowed kind is named with its reason.

Prints every offending symbol (mangled, and demangled when c++filt is present) with the members
that define it and exits 1; exits 0 when the contract holds.

    python3 tests/architecture/check_isa_symbols.py [--nm NM] ARCHIVE_OR_OBJECTS...
"""
import argparse
import collections
import re
import shutil
import subprocess
import sys

CODE = set("TWi")
DATA = set("VuRDBCGS")
# Shared data the contract allows, and why (check 3).
ALLOWED_DATA = [
    # The pointer to the C++ personality routine every object with exception tables carries.
    (re.compile(r"^DW\.ref\.__gxx_personality_v0$"), "personality-routine pointer"),
    # Inline constexpr variables of the project's and the libraries' headers (gnu_unique 'u' or
    # weak 'V'): read-only constants, laid out the same whatever the flags.
    (re.compile(r"^_ZN8streamrt.*[^v]$"), "constant of a shared header (inline variable)"),
    (re.compile(r"^_ZN(St|5xsimd).*"), "library constant (inline variable)"),
    # Guard variables and static locals of functions: one instance shared by every copy of
    # the function is what the language requires; the code that initialises them is in the
    # (per-level) function.
    (re.compile(r"^_ZGV"), "guard variable"),
    (re.compile(r"^_ZZ"), "static local of a function"),
    # typeinfo and its name of shared types.
    (re.compile(r"^_ZT[IS]"), "typeinfo"),
]
MEMBER = re.compile(r"^isa_([a-z0-9]+?)(_accel)?\.(cpp\.)?o$")


def level_of(member: str) -> str:
    m = MEMBER.match(member)
    return m.group(1) if m else "baseline"


def read_symbols(nm: str, paths):
    """[(member, type, symbol)] of the global defined symbols."""
    out = subprocess.run([nm, "--print-file-name", "--defined-only", "-g", *paths], capture_output=True,
                         text=True, check=True).stdout
    rows = []
    for line in out.splitlines():
        # "archive.a:member.o:0000000000000000 W symbol" or "file.o:0000000000000000 T symbol"
        parts = line.split()
        if len(parts) != 3:
            continue
        location, kind, symbol = parts
        member = location.rsplit(":", 1)[0].rsplit(":", 1)[-1].rsplit("/", 1)[-1]
        rows.append((member, kind, symbol))
    return rows


def demangle(symbols):
    if not symbols or not shutil.which("c++filt"):
        return {s: s for s in symbols}
    out = subprocess.run(["c++filt"], input="\n".join(symbols), capture_output=True, text=True).stdout
    return dict(zip(symbols, out.splitlines()))


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--nm", default="nm")
    ap.add_argument("paths", nargs="+")
    args = ap.parse_args()
    rows = read_symbols(args.nm, args.paths)
    members = sorted({m for m, _, _ in rows})
    levels = sorted({level_of(m) for m in members} - {"baseline"})
    if not levels:
        print("no isa_<level> objects found in", " ".join(args.paths))
        return 1

    defined = collections.defaultdict(list)  # symbol -> [(member, kind)]
    for member, kind, symbol in rows:
        defined[symbol].append((member, kind))

    problems = []  # (reason, symbol, [(member, kind)])
    allowed_data = collections.Counter()
    for symbol, where in defined.items():
        groups = {level_of(m) for m, _ in where}
        level_groups = groups - {"baseline"}
        if not level_groups:
            continue
        kinds = {k for _, k in where}
        if len(groups) > 1:
            if kinds & CODE:
                problems.append(("code shared across flag groups", symbol, where))
            else:
                reason = next((why for pattern, why in ALLOWED_DATA if pattern.match(symbol)), None)
                if reason is None:
                    problems.append(("data shared across flag groups, not on the allowed list", symbol, where))
                else:
                    allowed_data[reason] += 1
        if symbol.startswith("_ZN8streamrt") and kinds & CODE:
            for level in level_groups:
                if f"isa_{level}" not in symbol and not symbol.startswith("_ZN8streamrt11isa_kernels"):
                    problems.append((f"project function outside namespace isa_{level}", symbol, where))

    names = demangle(sorted({s for _, s, _ in problems}))
    for reason, symbol, where in sorted(problems, key=lambda p: (p[0], p[1])):
        print(f"{reason}: {symbol}\n    {names.get(symbol, symbol)}\n    defined in: "
              + ", ".join(f"{m} ({k})" for m, k in sorted(where)))
    code_in_levels = sum(1 for s, w in defined.items()
                         if {k for _, k in w} & CODE and {level_of(m) for m, _ in w} - {"baseline"})
    print(f"{len(members)} objects, levels {', '.join(levels)}; {code_in_levels} global code symbols in the "
          f"level objects; shared data allowed: "
          + (", ".join(f"{n} {why}" for why, n in sorted(allowed_data.items())) or "none"))
    print(f"{len(problems)} violation(s) of the kernel contract for instruction sets")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
