"""The ctypes layer against the C header, library discovery and the ABI check."""

from __future__ import annotations

import ctypes
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

import sogmm
from sogmm import _ffi

from conftest import header_path


def _header_text() -> str:
    h = header_path()
    if not h.is_file():
        pytest.skip(f"C header not found at {h}: these tests need a source checkout")
    text = h.read_text()
    text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
    return re.sub(r"//[^\n]*", " ", text)


def _exported_functions(text: str) -> dict[str, tuple[str, int]]:
    """name -> (return type, arity) of every SOGMM_API function in the header."""
    out = {}
    for m in re.finditer(r"SOGMM_API\s+([^;(]*?)\b(sogmm_\w+)\s*\(([^)]*)\)\s*;", text, flags=re.S):
        ret, name, args = " ".join(m.group(1).split()), m.group(2), " ".join(m.group(3).split())
        arity = 0 if args in ("", "void") else len(args.split(","))
        out[name] = (ret, arity)
    return out


def test_every_exported_function_is_declared_with_its_arity():
    exported = _exported_functions(_header_text())
    assert len(exported) >= 40, "the header parser found too few functions"
    declared = _ffi.declarations()
    assert set(declared) == set(exported), (
        f"missing in _ffi: {sorted(set(exported) - set(declared))}; "
        f"not in the header: {sorted(set(declared) - set(exported))}"
    )
    for name, (ret, arity) in exported.items():
        restype, argtypes = declared[name]
        assert len(argtypes) == arity, f"{name}: header has {arity} parameters, _ffi declares {len(argtypes)}"
        if ret == "void":
            assert restype is None, f"{name} returns void"
        elif ret == "sogmm_status":
            assert restype is ctypes.c_int32, f"{name} returns sogmm_status (int32)"
        elif ret == "const char*":
            assert restype is ctypes.c_char_p, name
        elif ret in ("uint32_t", "size_t"):
            assert restype in (ctypes.c_uint32, ctypes.c_size_t), name
        # Every declared symbol resolves in the loaded library.
        assert hasattr(_ffi.lib, name)


def test_constants_match_the_header():
    text = _header_text()
    defines = {m.group(1): int(m.group(2)) for m in re.finditer(r"#define\s+SOGMM_(\w+)\s+\(?(-?\d+)\)?\s", text)}
    checked = 0
    for name, value in defines.items():
        if name.startswith(("OPT_", "INFO_", "MAP_", "COLOR_", "MODE_COUNTER_")):
            assert getattr(_ffi, name) == value, name
            checked += 1
    assert checked >= 40
    assert defines["ABI_VERSION"] == _ffi.ABI_VERSION == sogmm.ABI_VERSION
    for status_name, cls in [("E_INVALID_ARG", sogmm.InvalidArgumentError), ("E_INVALID_DATA", sogmm.InvalidDataError),
                             ("E_NUMERIC", sogmm.NumericError), ("E_IO", sogmm.SogmmIOError),
                             ("E_FORMAT", sogmm.FormatError), ("E_LIMIT", sogmm.LimitError),
                             ("E_NOMEM", sogmm.SogmmMemoryError), ("E_BUFFER_TOO_SMALL", sogmm.BufferTooSmallError),
                             ("E_NOT_FOUND", sogmm.NotFoundError), ("E_INTERNAL", sogmm.InternalError),
                             ("E_NULL_ARG", sogmm.NullArgumentError), ("E_CANCELLED", sogmm.CancelledError)]:
        assert cls.status == defines[status_name], status_name
    from sogmm import progress
    stages = {name: value for name, value in defines.items() if name.startswith("STAGE_")}
    assert len(stages) >= 5
    for name, value in stages.items():
        assert getattr(progress, name) == value, name


def test_versions():
    assert _ffi.lib.sogmm_abi_version() == sogmm.ABI_VERSION
    assert sogmm.library_version() == sogmm.__version__
    assert Path(sogmm.library_path()).is_file()


def _import_in_subprocess(env_extra: dict) -> subprocess.CompletedProcess:
    env = dict(os.environ)
    env.update(env_extra)
    pkg_parent = str(Path(sogmm.__file__).resolve().parents[1])
    env["PYTHONPATH"] = pkg_parent + os.pathsep + env.get("PYTHONPATH", "")
    return subprocess.run([sys.executable, "-c", "import sogmm; print(sogmm.library_path())"],
                          env=env, capture_output=True, text=True, timeout=120)


def test_library_path_override_is_used():
    r = _import_in_subprocess({"SOGMM_LIBRARY_PATH": sogmm.library_path()})
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == sogmm.library_path()


def test_missing_library_is_a_clear_import_error(tmp_path):
    r = _import_in_subprocess({"SOGMM_LIBRARY_PATH": str(tmp_path / "nope" / "libsogmm.so")})
    assert r.returncode != 0
    assert "ImportError" in r.stderr and "cannot load the C library libsogmm" in r.stderr
    assert "SOGMM_LIBRARY_PATH" in r.stderr


def test_wrong_library_is_rejected(tmp_path):
    import ctypes.util

    libm = ctypes.util.find_library("m")
    if libm is None:
        pytest.skip("no libm to stand in for a wrong library")
    path = None
    for d in ("/lib/x86_64-linux-gnu", "/usr/lib/x86_64-linux-gnu", "/lib64", "/usr/lib64", "/lib", "/usr/lib"):
        if os.path.isfile(os.path.join(d, libm)):
            path = os.path.join(d, libm)
            break
    if path is None:
        pytest.skip(f"cannot locate {libm} on disk")
    r = _import_in_subprocess({"SOGMM_LIBRARY_PATH": path})
    assert r.returncode != 0
    assert "not libsogmm" in r.stderr


def test_sanitizer_build_dirs_are_skipped(tmp_path):
    (tmp_path / "build-asan").mkdir()
    assert _ffi._is_sanitizer_build(tmp_path / "build-asan")
    other = tmp_path / "build-x"
    other.mkdir()
    (other / "CMakeCache.txt").write_text("SOGMM_SANITIZE:BOOL=ON\n")
    assert _ffi._is_sanitizer_build(other)
    plain = tmp_path / "build-y"
    plain.mkdir()
    (plain / "CMakeCache.txt").write_text("SOGMM_SANITIZE:BOOL=OFF\n")
    assert not _ffi._is_sanitizer_build(plain)
