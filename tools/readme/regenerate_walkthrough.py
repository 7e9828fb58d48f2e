#!/usr/bin/env python3
"""Re-runs the README's command-line walk-through and writes the outputs back.

Every ```console block of README.md is a transcript: lines starting with "$ "
are commands (continued by a trailing backslash), the lines after them are
what the command printed. This script runs the commands in order, in one
scratch folder beside the checkout (so `../shared/...` resolves exactly as it
does for a user in the checkout), with the freshly built `sogmm` tool first on
PATH, and replaces each command's printed lines with what it prints now
(stdout and stderr interleaved, as a terminal shows them). Shell variables set
by a "$ NAME=value" line carry over to later commands.

The figures in those transcripts (timings, PSNR, component counts) therefore
always come from the code they describe. Run it on an idle machine after
`cmake --build build`:

    python3 tools/readme/regenerate_walkthrough.py            # rewrite README.md
    python3 tools/readme/regenerate_walkthrough.py --check    # exit 1 if a command fails

A command that exits non-zero stops the script with its output and the README
is left untouched. Numbers quoted in the prose around the blocks are not
rewritten: compare them with the new transcripts (`git diff README.md`).
"""
from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
ASSIGNMENT = re.compile(r"^([A-Za-z_][A-Za-z0-9_]*)=(\S+)$")


def parse_blocks(lines: list[str]) -> list[tuple[int, int]]:
    """(first, last) line indices of the body of every ```console block."""
    blocks, start = [], None
    for i, line in enumerate(lines):
        if line.strip() == "```console":
            start = i + 1
        elif line.strip() == "```" and start is not None:
            blocks.append((start, i))
            start = None
    return blocks


def split_transcript(body: list[str]) -> list[list[str]]:
    """The block's commands, each as its (continued) command lines."""
    commands, i = [], 0
    while i < len(body):
        if not body[i].startswith("$ "):
            i += 1
            continue
        command = [body[i]]
        while command[-1].endswith("\\") and i + 1 < len(body):
            i += 1
            command.append(body[i])
        commands.append(command)
        i += 1
    return commands


def run(command_lines: list[str], env_prefix: str, cwd: Path, env: dict) -> list[str]:
    text = "\n".join(command_lines)[2:]  # drop "$ "
    script = env_prefix + text
    result = subprocess.run(["bash", "-o", "pipefail", "-c", script], cwd=cwd, env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    output = result.stdout.rstrip("\n").split("\n") if result.stdout.strip() else []
    if result.returncode != 0:
        sys.exit(f"regenerate_walkthrough: `{text}` exited {result.returncode}:\n" + "\n".join(output))
    return output


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--readme", type=Path, default=REPO / "README.md")
    parser.add_argument("--sogmm", type=Path, default=REPO / "build" / "tools" / "sogmm" / "sogmm",
                        help="the sogmm executable the transcripts call")
    parser.add_argument("--check", action="store_true",
                        help="run the commands and fail if one fails; do not rewrite the README "
                             "(skips with a message when ../shared is absent: the ctest readme_walkthrough)")
    args = parser.parse_args()

    if not args.sogmm.exists():
        sys.exit(f"regenerate_walkthrough: {args.sogmm} not found; build first (cmake --build build)")
    if not (REPO.parent / "shared" / "data" / "rgbd").is_dir():
        message = "../shared/data/rgbd is absent beside the checkout; the walk-through runs on the real frames"
        if args.check:
            print(f"SKIP: {message}")
            return 0
        sys.exit(f"regenerate_walkthrough: {message}")
    env = dict(os.environ)
    env["PATH"] = str(args.sogmm.resolve().parent) + os.pathsep + env.get("PATH", "")

    lines = args.readme.read_text().split("\n")
    scratch = Path(tempfile.mkdtemp(prefix=".sogmm-walkthrough-", dir=REPO.parent))
    rewritten, env_prefix, cursor = [], "", 0
    try:
        for first, last in parse_blocks(lines):
            rewritten += lines[cursor:first]
            for command in split_transcript(lines[first:last]):
                print(command[0], file=sys.stderr, flush=True)
                output = run(command, env_prefix, scratch, env)
                rewritten += command + output
                assignment = ASSIGNMENT.match(command[0][2:].strip())
                if assignment and len(command) == 1:
                    env_prefix += f"{assignment.group(1)}={assignment.group(2)}; "
            cursor = last
        rewritten += lines[cursor:]
    finally:
        shutil.rmtree(scratch, ignore_errors=True)

    if args.check:
        return 0
    args.readme.write_text("\n".join(rewritten))
    print(f"rewrote the console blocks of {args.readme}; compare the prose's figures with them", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
