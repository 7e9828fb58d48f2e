#!/usr/bin/env python3
"""Writes the option registry's mirrors into the files that carry them.

The option registry (core/include/sogmm/options.hpp, rows in
core/src/option_table.cpp) is the one source of every option's key, type,
range, default, unit and documentation. Files that cannot read it at run
time hold a generated copy between two marker lines:

    ... BEGIN GENERATED option keys ...
    ... END GENERATED option keys ...

This script replaces what stands between them with what
sogmm-option-mirrors (tools/options/option_mirrors.cpp, built against the
core) prints for that file. With --check it writes nothing and fails, with a
diff and the command to run, when a file's block is not what it would write
(ctest options_registry runs it so).

Usage:
    cmake --build build --target sogmm-option-mirrors
    python3 tools/options/regenerate.py [--check] [--generator PATH]
"""
import argparse
import difflib
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
DEFAULT_GENERATOR = ROOT / "build/tools/options/sogmm-option-mirrors"
BEGIN = "BEGIN GENERATED option keys"
END = "END GENERATED option keys"

# file -> the generator's block for it
MIRRORS = {
    "capi/include/sogmm/sogmm.h": "header",
    "spec/api.md": "spec",
    "bindings/rust/sogmm-sys/src/lib.rs": "rust",
    "bindings/python/src/sogmm/_ffi.py": "python",
    "bindings/go/options.go": "go",
}


def spliced(text, block, path):
    """`text` with the lines between its two marker lines replaced by `block`."""
    lines = text.splitlines(keepends=True)
    begins = [i for i, line in enumerate(lines) if BEGIN in line]
    ends = [i for i, line in enumerate(lines) if END in line]
    if len(begins) != 1 or len(ends) != 1 or ends[0] < begins[0]:
        raise SystemExit(f"{path}: needs exactly one '{BEGIN}' line followed by one '{END}' line")
    return "".join(lines[: begins[0] + 1]) + block + "".join(lines[ends[0]:])


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--check", action="store_true", help="write nothing; fail when a block is stale")
    parser.add_argument("--generator", type=Path, default=DEFAULT_GENERATOR, help="sogmm-option-mirrors")
    parser.add_argument("--root", type=Path, default=ROOT, help="the source tree")
    args = parser.parse_args()
    if not args.generator.is_file():
        raise SystemExit(f"{args.generator} not found: cmake --build build --target sogmm-option-mirrors")
    stale = []
    for rel, block_name in MIRRORS.items():
        path = args.root / rel
        block = subprocess.run([str(args.generator), block_name], check=True, capture_output=True,
                               text=True).stdout
        old = path.read_text()
        new = spliced(old, block, rel)
        if new == old:
            continue
        stale.append(rel)
        if args.check:
            sys.stdout.writelines(difflib.unified_diff(old.splitlines(keepends=True), new.splitlines(keepends=True),
                                                       f"a/{rel}", f"b/{rel} (generated)", n=1))
        else:
            path.write_text(new)
            print(f"rewrote the option block of {rel}")
    if args.check and stale:
        print(f"\nSTALE: the option block of {', '.join(stale)} differs from the registry "
              f"(core/src/option_table.cpp). Fix with:\n"
              f"    python3 tools/options/regenerate.py --generator {args.generator}")
        return 1
    if args.check:
        print(f"{len(MIRRORS)} generated option blocks match the registry")
    return 0


if __name__ == "__main__":
    sys.exit(main())
