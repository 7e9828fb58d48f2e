#!/usr/bin/env python3
"""Every layer's option keys and defaults against the library's registry.

The option registry (core/include/sogmm/options.hpp) is the one source of
each option's key, type, range, default and documentation; the C API
reports it through sogmm_option_keys / sogmm_option_get_info. This check
fails when a copy of it disagrees:

- the generated blocks (the SOGMM_OPT_* macros and their documentation in
  sogmm.h, spec/api.md's option tables, the Rust, Python and Go key
  constants) differ from what tools/options/regenerate.py writes from the
  registry; the message names the command that rewrites them;
- a keyword of Python's public API that names an option has a default other
  than the registry's (the package reads them from the library).

Usage: check_options.py LIBSOGMM_PATH REPO_ROOT SOGMM_OPTION_MIRRORS_PATH
"""
import ctypes
import inspect
import math
import subprocess
import sys
from pathlib import Path

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


def same(a, b):
    return a == b or (math.isnan(a) and math.isnan(b)) or math.isclose(a, b, rel_tol=1e-12)


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
    lib_path, root, generator = sys.argv[1], Path(sys.argv[2]), sys.argv[3]
    stale = subprocess.run([sys.executable, str(root / "tools/options/regenerate.py"), "--check",
                            "--generator", generator, "--root", str(root)])
    rows = registry(lib_path)
    problems = []
    n_python = check_python_defaults(rows, root, problems)
    for p in problems:
        print("MISMATCH", p)
    print(f"{len(rows)} options; {n_python} Python keyword defaults checked: {len(problems)} mismatches")
    return 1 if problems or stale.returncode != 0 else 0


if __name__ == "__main__":
    sys.exit(main())
