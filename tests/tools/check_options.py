#!/usr/bin/env python3
"""Every layer's option keys and defaults against the library's registry.

The option registry (core/include/sogmm/options.hpp) is the one source of
each option's key, type, range and default; the C API reports it through
sogmm_option_keys / sogmm_option_get_info. This check reads the registry
from the built library and fails on any copy that disagrees with it:

- sogmm.h: every SOGMM_OPT_* macro is a registry key with that name and
  number, and the "default X" of its comment is the registry's default;
- spec/api.md: the option table's key, type and default columns;
- Rust (sogmm-sys) and Python (_ffi.py) key constants: names and numbers
  (Go takes the header's macros through cgo: nothing to compare);
- Python: every keyword of the public API that names an option has the
  registry's default (the package reads them from the library).

Usage: check_options.py LIBSOGMM_PATH REPO_ROOT
"""
import ctypes
import inspect
import math
import re
import sys
from pathlib import Path

SENTINELS = {
    "SOGMM_REG_COVAR_AUTO": -1.0,
    "SOGMM_DEQUANTISE_AUTO": -1.0,
    "SOGMM_MODE_COUNTER_FLAT_BINNED": 0.0,
    "SOGMM_FUSION_HELLINGER": 0.0,
}


class Info(ctypes.Structure):
    _fields_ = [
        ("struct_size", ctypes.c_size_t),
        ("key", ctypes.c_int32),
        ("type", ctypes.c_int32),
        ("name", ctypes.c_char_p),
        ("default_f64", ctypes.c_double),
        ("lower_f64", ctypes.c_double),
        ("upper_f64", ctypes.c_double),
        ("default_i64", ctypes.c_int64),
        ("lower_i64", ctypes.c_int64),
        ("upper_i64", ctypes.c_int64),
        ("range", ctypes.c_char_p),
        ("unit", ctypes.c_char_p),
        ("doc", ctypes.c_char_p),
    ]


def registry(lib_path):
    lib = ctypes.CDLL(lib_path)
    count = ctypes.c_size_t()
    assert lib.sogmm_option_keys(None, 0, ctypes.byref(count)) == 0
    keys = (ctypes.c_int32 * count.value)()
    assert lib.sogmm_option_keys(keys, count.value, ctypes.byref(count)) == 0
    rows = {}
    for key in keys:
        info = Info(struct_size=ctypes.sizeof(Info))
        assert lib.sogmm_option_get_info(key, ctypes.byref(info)) == 0, key
        is_f64 = info.type == 0
        rows[info.name.decode()] = {
            "key": key,
            "type": "f64" if is_f64 else "i64",
            "default": info.default_f64 if is_f64 else float(info.default_i64),
        }
    return rows


def number(text):
    """The value a default cell or comment states: a number or a sentinel."""
    text = text.strip().strip("`").rstrip(".,;:")
    if text in SENTINELS:
        return SENTINELS[text]
    m = re.match(r"^([-+]?[0-9.]+(?:e[-+]?[0-9]+)?)", text)
    return float(m.group(1)) if m else None


def same(a, b):
    return a == b or (math.isnan(a) and math.isnan(b)) or math.isclose(a, b, rel_tol=1e-12)


def check_header(rows, root, problems):
    text = (root / "capi/include/sogmm/sogmm.h").read_text()
    seen = set()
    for m in re.finditer(r"#define (SOGMM_OPT_\w+) (\d+)\s*/\*(.*?)\*/", text, re.S):
        name, key, comment = m.group(1), int(m.group(2)), m.group(3)
        seen.add(name)
        row = rows.get(name)
        if row is None:
            problems.append(f"sogmm.h: {name} = {key} is not in the registry")
            continue
        if row["key"] != key:
            problems.append(f"sogmm.h: {name} = {key}, registry {row['key']}")
        if not comment.strip().startswith(row["type"]):
            problems.append(f"sogmm.h: {name}'s comment does not start with its type {row['type']}")
        d = re.search(r"default ([^\s:;,]+)", comment)
        if not d or number(d.group(1)) is None or not same(number(d.group(1)), row["default"]):
            problems.append(f"sogmm.h: {name}'s comment states default "
                            f"{d.group(1) if d else '(none)'}, registry {row['default']}")
    for name in rows.keys() - seen:
        problems.append(f"sogmm.h: no #define for {name}")


def check_spec(rows, root, problems):
    seen = set()
    for line in (root / "spec/api.md").read_text().splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) < 5 or not re.fullmatch(r"`SOGMM_OPT_\w+`", cells[0]):
            continue
        name = cells[0].strip("`")
        seen.add(name)
        row = rows.get(name)
        if row is None:
            problems.append(f"spec/api.md: {name} is not in the registry")
            continue
        if int(cells[1]) != row["key"] or cells[2] != row["type"]:
            problems.append(f"spec/api.md: {name} is {cells[1]} {cells[2]}, registry {row['key']} {row['type']}")
        d = number(cells[4].split(":")[0].split(" ")[0])
        if d is None or not same(d, row["default"]):
            problems.append(f"spec/api.md: {name} default '{cells[4][:40]}', registry {row['default']}")
    for name in rows.keys() - seen:
        problems.append(f"spec/api.md: the option table has no row for {name}")


def check_constants(rows, path, pattern, prefix, problems):
    text = path.read_text()
    found = {prefix + m.group(1): int(m.group(2)) for m in re.finditer(pattern, text)}
    for name, row in rows.items():
        if name not in found:
            problems.append(f"{path}: no constant for {name}")
        elif found[name] != row["key"]:
            problems.append(f"{path}: {name} = {found[name]}, registry {row['key']}")
    for name in found.keys() - rows.keys():
        problems.append(f"{path}: {name} is not in the registry")


def check_python_defaults(rows, root, problems):
    sys.path.insert(0, str(root / "bindings/python/src"))
    import sogmm
    from sogmm import _ffi

    by_kwarg = {}
    for key, kwarg in _ffi.OPTION_NAMES.items():
        name = next(n for n, r in rows.items() if r["key"] == key)
        by_kwarg.setdefault(kwarg, []).append(rows[name]["default"])
    checked = 0
    for obj_name in dir(sogmm):
        obj = getattr(sogmm, obj_name)
        members = [obj] + [m for _, m in inspect.getmembers(obj, callable)] if inspect.isclass(obj) else [obj]
        for fn in members:
            try:
                params = inspect.signature(fn).parameters
            except (TypeError, ValueError):
                continue
            for p in params.values():
                if p.name not in by_kwarg or p.default is inspect.Parameter.empty or p.default is None:
                    continue
                if isinstance(p.default, str):  # "auto" spelled as a word
                    continue
                checked += 1
                want = by_kwarg[p.name]
                if not any(same(float(p.default), w) for w in want):
                    problems.append(f"python: {getattr(fn, '__qualname__', fn)}({p.name}={p.default!r}), "
                                    f"registry {want}")
    if checked == 0:
        problems.append("python: no keyword default found to check (did the names change?)")
    return checked


def main():
    lib_path, root = sys.argv[1], Path(sys.argv[2])
    rows = registry(lib_path)
    problems = []
    check_header(rows, root, problems)
    check_spec(rows, root, problems)
    check_constants(rows, root / "bindings/rust/sogmm-sys/src/lib.rs",
                    r"pub const SOGMM_OPT_(\w+): sogmm_key = (\d+);", "SOGMM_OPT_", problems)
    check_constants(rows, root / "bindings/python/src/sogmm/_ffi.py", r"(?m)^OPT_(\w+) = (\d+)$", "SOGMM_OPT_",
                    problems)
    n_python = check_python_defaults(rows, root, problems)
    for p in problems:
        print("MISMATCH", p)
    print(f"{len(rows)} options; header, spec/api.md, Rust and Python keys, {n_python} Python keyword defaults "
          f"checked: {len(problems)} mismatches")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
