#!/usr/bin/env python3
"""Where a directory of map deltas spends its bytes (issue 33): per delta on
average, the header and metadata, the packed key/values (spec/format.md
2.5.1), the arrays, and the explicit components they carry split by the step
that uses them: `merge` components (new, or a revisit refit's replacements)
against the positions the `remove`, `set` and `drop` steps name.

Reads the files with the independent Python reader of the conformance tests
(tests/conformance/python_reader), so it needs no build.

Usage (from the repository root):
    python3 tools/sogmm-perf/delta_contents.py DIR [DIR ...]
"""
import collections
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "tests", "conformance", "python_reader"))
import sogmm_reader  # noqa: E402


def contents(directory):
    total = collections.Counter()
    names = sorted(os.listdir(directory))
    for name in names:
        data = open(os.path.join(directory, name), "rb").read()
        head = 32 + (int.from_bytes(data[24:28], "little") + 7) // 8 * 8
        located = dict(sogmm_reader.read(data, delta=True, metadata_only=True)["key_values"])
        packed = int(located["packed_key_values"].split()[1]) if "packed_key_values" in located else 0
        d = sogmm_reader.read(data, delta=True)
        kv = dict(d["key_values"])
        total["bytes"] += len(data)
        total["header_and_metadata"] += head
        total["packed_key_values"] += packed
        total["arrays"] += len(data) - head - 4 - packed
        for line in kv["delta_ops"].splitlines():
            step = line.split()
            if step[0] == "merge":
                total["merged_components"] += int(step[1])
            else:
                total[step[0] + "_positions"] += len(step) - 1
                total["deltas_with_" + step[0]] += 1
    return len(names), total


def main():
    for directory in sys.argv[1:]:
        n, t = contents(directory)
        per = {k: round(v / n, 1) for k, v in sorted(t.items()) if not k.startswith("deltas_with")}
        explicit = t["merged_components"] + t["set_positions"]  # every explicit component a merge or set uses
        per["array_bytes_per_explicit_component"] = round(t["arrays"] / max(1, explicit), 1)
        counts = {k: v for k, v in sorted(t.items()) if k.startswith("deltas_with")}
        print("%s: %d deltas; per delta %s; %s" % (directory, n, per, counts))


if __name__ == "__main__":
    main()
