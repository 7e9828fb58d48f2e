"""ctypes layer over libsogmm (the C API of capi/include/sogmm/sogmm.h).

Only handles, scalars, pointers and the option-info struct cross the
boundary. Every exported function is
declared in ``_DECLARATIONS`` below; a test parses the C header and checks
that the names and arities match.

Library discovery (first match wins):
  1. the ``SOGMM_LIBRARY_PATH`` environment variable (a file path);
  2. the copy bundled in the package (``sogmm/_lib/``), as installed from a wheel;
  3. the build tree of a source checkout (``<repo>/build*/capi/libsogmm.so*``,
     newest first, sanitizer builds skipped).
The library's ``sogmm_abi_version()`` must equal :data:`ABI_VERSION`.
"""

from __future__ import annotations

import ctypes
import os
import sys
import types
from ctypes import POINTER, c_char_p, c_double, c_int32, c_int64, c_size_t, c_uint8, c_uint32, c_uint64, c_void_p
from pathlib import Path

import numpy as np

from .errors import error_for_status

#: The SOGMM_ABI_VERSION this package was written for.
ABI_VERSION = 2

# ---- constants (mirror sogmm.h) ------------------------------------------
OK = 0
E_NOT_FOUND = -10

# BEGIN GENERATED option keys (tools/options/regenerate.py, from core/src/option_table.cpp)
OPT_BANDWIDTH = 100
OPT_N_COMPONENTS = 101
OPT_TOL = 102
OPT_REG_COVAR = 103
OPT_MAX_ITER = 104
OPT_SEED = 105
OPT_THREADS = 106
OPT_MODE_COUNTER = 107
OPT_TRUNCATION_NATS = 108
OPT_N_INIT = 109
OPT_DEQUANTISE_DEPTH = 110
OPT_EM_ACCELERATION = 111
OPT_TOL_STANDARD_ERRORS = 131
OPT_WARM_MAX_ITER = 145
OPT_DEPTH_SCALE = 200
OPT_DEPTH_MIN = 201
OPT_DEPTH_MAX = 202
OPT_DECIMATION = 203
OPT_ZSTD_LEVEL = 300
OPT_FLOAT64 = 301
OPT_COMPRESS = 302
OPT_ARRAY_PRECISION = 303
OPT_MAX_DECODED_BYTES = 400
OPT_VERIFY_CHECKSUMS = 401
OPT_SAMPLE_TRUNCATION = 500
OPT_QUERY_TRUNCATION_NATS = 501
OPT_RENDER_SURFACE_SIGMA = 502
OPT_MAP_NOVELTY = 600
OPT_MAP_NOVELTY_THRESHOLD = 601
OPT_MAP_BATCH_SIZE = 602
OPT_MAP_FUSION = 603
OPT_MAP_FUSION_METHOD = 604
OPT_MAP_FUSION_THRESHOLD = 605
OPT_MAP_WARM_START = 606
OPT_MAP_NOVELTY_BANDWIDTH_SCALE = 607
OPT_MAP_REVISIT_REFIT_RATIO = 608
OPT_MAP_DELTA_HISTORY = 609
OPT_MAP_FREE_SPACE_CARVE = 620
OPT_MAP_COMPONENT_PRECISION = 630
OPT_OCCUPANCY_SIGMA = 700
OPT_OCCUPANCY_THICKNESS = 701
OPT_SURFACE_DISC_SIGMAS = 702
OPT_REGISTRATION_MAX_ITER = 800
OPT_REGISTRATION_TOL = 801
OPT_REGISTRATION_OUTLIER_RATIO = 802
OPT_REGISTRATION_USE_GRAY = 803
OPT_REGISTRATION_LEVELS = 804
OPT_REGISTRATION_COARSE_SIGMA = 805
OPT_REGISTRATION_MIN_INLIER_RATIO = 806
OPT_REGISTRATION_DEGENERACY_RATIO = 807
OPT_REGISTRATION_MIN_POINTS = 808
OPT_REGISTRATION_DEPTH_NOISE = 809
OPT_TRACKING_ODOMETRY = 810
OPT_TRACKING_MAX_DISAGREEMENT = 811
# END GENERATED option keys
DEQUANTISE_AUTO = -1
MODE_COUNTER_FLAT_BINNED = 0
MODE_COUNTER_GAUSSIAN_BLURRING = 1
REGISTRATION_STATUS = {0: "converged", 1: "not_converged", 2: "low_fitness", 3: "degenerate"}
OCCUPANCY_FREE = 0
OCCUPANCY_OCCUPIED = 1
OCCUPANCY_UNKNOWN = 2
FUSION_HELLINGER = 0
FUSION_KL = 1

COLOR_GRAY8 = 1
COLOR_RGB8 = 2
COLOR_GRAY_F32 = 3

# Info keys are 10000 and up, disjoint from the option keys.
INFO_SUPPORT_SIZE = 10001
INFO_CREATED_UNIX_MS = 10002
INFO_FIT_ITERATIONS = 10100
INFO_FIT_CONVERGED = 10101
INFO_FIT_LOG_LIKELIHOOD = 10102
INFO_FIT_BANDWIDTH = 10103
INFO_FIT_N_COMPONENTS_REQUESTED = 10104
INFO_FIT_TOL = 10105
INFO_FIT_REG_COVAR = 10106
INFO_FIT_MAX_ITER = 10107
INFO_FIT_SEED = 10108
INFO_FIT_N_POINTS = 10150
INFO_FIT_SECONDS_MODE_COUNT = 10151
INFO_FIT_SECONDS_SEEDING = 10152
INFO_FIT_SECONDS_EM = 10153
INFO_FIT_SECONDS_TOTAL = 10154
INFO_FIT_N_INIT = 10155
INFO_FIT_RUN = 10156
INFO_CAMERA_WIDTH = 10200
INFO_CAMERA_HEIGHT = 10201
INFO_CAMERA_FX = 10202
INFO_CAMERA_FY = 10203
INFO_CAMERA_CX = 10204
INFO_CAMERA_CY = 10205
INFO_CAMERA_DECIMATION = 10206
INFO_CAMERA_DEPTH_SCALE = 10207
INFO_CAMERA_DEPTH_MIN = 10208
INFO_CAMERA_DEPTH_MAX = 10209

# Map statistic keys (SOGMM_MAP_*): totals, then what one insert did.
MAP_N_COMPONENTS = 20000
MAP_N_PENDING = 20001
MAP_N_FRAMES = 20002
MAP_N_FLUSHES = 20003
MAP_N_FUSED = 20004
MAP_N_REFITS = 20005
MAP_REVISION = 20006
MAP_FRAME_N_POINTS = 20100
MAP_FRAME_N_NOVEL = 20101
MAP_FRAME_N_COMPONENTS = 20102
MAP_FRAME_FLUSHED = 20103
MAP_FRAME_N_REPLACED = 20104
MAP_FRAME_MS_NOVELTY = 20150
MAP_FRAME_MS_FIT = 20151
MAP_FRAME_MS_MERGE = 20152

# ---- argument types ------------------------------------------------------
_C = "C_CONTIGUOUS"
F32_IN = np.ctypeslib.ndpointer(dtype=np.float32, flags=_C)
F32_OUT = np.ctypeslib.ndpointer(dtype=np.float32, flags=(_C, "WRITEABLE"))
F64_IN = np.ctypeslib.ndpointer(dtype=np.float64, flags=_C)
F64_OUT = np.ctypeslib.ndpointer(dtype=np.float64, flags=(_C, "WRITEABLE"))
U16_IN = np.ctypeslib.ndpointer(dtype=np.uint16, flags=_C)
U8_IN = np.ctypeslib.ndpointer(dtype=np.uint8, flags=_C)

HANDLE = c_void_p  # sogmm_model*, sogmm_options*, sogmm_buffer*
HANDLE_OUT = POINTER(c_void_p)  # sogmm_xxx**
STATUS = c_int32
KEY = c_int32

# sogmm_progress_fn: (stage, step, total, log_likelihood, user_data) -> 0 / non-zero = cancel.
PROGRESS_FN = ctypes.CFUNCTYPE(c_int32, c_int32, c_uint64, c_uint64, c_double, c_void_p)

# name -> (restype, argtypes). Keep in the order of sogmm.h.
_DECLARATIONS: dict[str, tuple[object, list[object]]] = {
    "sogmm_version_number": (c_uint32, []),
    "sogmm_version_string": (c_char_p, []),
    "sogmm_abi_version": (c_uint32, []),
    "sogmm_status_string": (c_char_p, [STATUS]),
    "sogmm_last_error": (c_char_p, []),
    "sogmm_options_create": (STATUS, [HANDLE_OUT]),
    "sogmm_options_clone": (STATUS, [HANDLE_OUT, HANDLE]),
    "sogmm_options_free": (None, [HANDLE]),
    "sogmm_options_set_f64": (STATUS, [HANDLE, KEY, c_double]),
    "sogmm_options_set_i64": (STATUS, [HANDLE, KEY, c_int64]),
    "sogmm_options_get_f64": (STATUS, [HANDLE, KEY, POINTER(c_double)]),
    "sogmm_options_get_i64": (STATUS, [HANDLE, KEY, POINTER(c_int64)]),
    "sogmm_options_set_progress": (STATUS, [HANDLE, PROGRESS_FN, c_void_p]),
    "sogmm_option_get_info": (STATUS, [KEY, ctypes.c_void_p]),
    "sogmm_option_keys": (STATUS, [POINTER(KEY), c_size_t, POINTER(c_size_t)]),
    "sogmm_fit_points_f32": (STATUS, [HANDLE_OUT, F32_IN, c_size_t, HANDLE, HANDLE]),
    "sogmm_frame_from_arrays": (STATUS, [HANDLE_OUT, c_uint32, c_uint32, U16_IN, c_void_p, c_int32]),
    "sogmm_frame_read": (STATUS, [HANDLE_OUT, c_char_p, c_char_p]),
    "sogmm_frame_decode": (STATUS, [HANDLE_OUT, c_void_p, c_size_t, c_void_p, c_size_t]),
    "sogmm_frame_free": (None, [HANDLE]),
    "sogmm_frame_width": (c_uint32, [HANDLE]),
    "sogmm_frame_height": (c_uint32, [HANDLE]),
    "sogmm_frame_depth": (c_void_p, [HANDLE]),
    "sogmm_frame_color": (c_void_p, [HANDLE]),
    "sogmm_frame_color_format": (c_int32, [HANDLE]),
    "sogmm_frame_set_intrinsics": (STATUS, [HANDLE, c_double, c_double, c_double, c_double]),
    "sogmm_fit_frame": (STATUS, [HANDLE_OUT, HANDLE, HANDLE]),
    "sogmm_frame_to_points_f32": (STATUS, [F32_OUT, c_size_t, POINTER(c_size_t), HANDLE, HANDLE]),
    "sogmm_model_from_arrays_f32": (STATUS, [HANDLE_OUT, c_size_t, F32_IN, F32_IN, F32_IN, c_uint64]),
    "sogmm_model_clone": (STATUS, [HANDLE_OUT, HANDLE]),
    "sogmm_model_free": (None, [HANDLE]),
    "sogmm_model_n_components": (STATUS, [HANDLE, POINTER(c_size_t)]),
    "sogmm_model_get_weights_f32": (STATUS, [HANDLE, F32_OUT, c_size_t]),
    "sogmm_model_get_means_f32": (STATUS, [HANDLE, F32_OUT, c_size_t]),
    "sogmm_model_get_covariances_f32": (STATUS, [HANDLE, F32_OUT, c_size_t]),
    "sogmm_model_get_info_f64": (STATUS, [HANDLE, KEY, POINTER(c_double)]),
    "sogmm_model_get_info_i64": (STATUS, [HANDLE, KEY, POINTER(c_int64)]),
    "sogmm_model_set_info_f64": (STATUS, [HANDLE, KEY, c_double]),
    "sogmm_model_set_info_i64": (STATUS, [HANDLE, KEY, c_int64]),
    "sogmm_model_get_pose": (STATUS, [HANDLE, F64_OUT]),
    "sogmm_model_set_pose": (STATUS, [HANDLE, F64_IN]),
    "sogmm_model_clear_pose": (STATUS, [HANDLE]),
    "sogmm_model_get_value": (STATUS, [HANDLE, c_char_p, POINTER(c_char_p)]),
    "sogmm_model_set_value": (STATUS, [HANDLE, c_char_p, c_char_p]),
    "sogmm_model_value_count": (STATUS, [HANDLE, POINTER(c_size_t)]),
    "sogmm_model_value_at": (STATUS, [HANDLE, c_size_t, POINTER(c_char_p), POINTER(c_char_p)]),
    "sogmm_model_sample_f32": (STATUS, [HANDLE, c_size_t, c_uint64, c_int32, HANDLE, F32_OUT]),
    "sogmm_model_regress_gray_f32": (STATUS, [HANDLE, F32_IN, c_size_t, HANDLE, F32_OUT, F32_OUT]),
    "sogmm_model_score_samples_f32": (STATUS, [HANDLE, F32_IN, c_size_t, c_int32, HANDLE, F64_OUT]),
    "sogmm_psnr_images_f32": (STATUS, [F32_IN, F32_IN, c_size_t, c_double, F64_OUT, F64_OUT]),
    "sogmm_model_merge": (STATUS, [HANDLE_OUT, HANDLE, HANDLE]),
    "sogmm_model_transform": (STATUS, [HANDLE_OUT, HANDLE, F64_IN]),
    "sogmm_model_save": (STATUS, [HANDLE, c_char_p, HANDLE]),
    "sogmm_model_load": (STATUS, [HANDLE_OUT, c_char_p, HANDLE]),
    "sogmm_model_save_to_memory": (STATUS, [HANDLE_OUT, HANDLE, HANDLE]),
    "sogmm_model_load_from_memory": (STATUS, [HANDLE_OUT, c_void_p, c_size_t, HANDLE]),
    "sogmm_map_create": (STATUS, [HANDLE_OUT, HANDLE]),
    "sogmm_map_free": (None, [HANDLE]),
    "sogmm_map_insert_points_f32": (STATUS, [HANDLE, F32_IN, c_size_t, F64_IN]),
    "sogmm_map_insert_frame": (STATUS, [HANDLE, HANDLE, F64_IN]),
    # guess, inserted_out and info_out may be NULL: c_void_p.
    "sogmm_map_track_frame": (STATUS, [HANDLE, HANDLE, c_void_p, F64_OUT, c_void_p, c_void_p]),
    "sogmm_map_flush": (STATUS, [HANDLE]),
    "sogmm_map_discard_pending": (STATUS, [HANDLE, POINTER(c_uint64)]),
    "sogmm_map_set_progress": (STATUS, [HANDLE, PROGRESS_FN, c_void_p]),
    "sogmm_map_get_i64": (STATUS, [HANDLE, KEY, POINTER(c_int64)]),
    "sogmm_map_frame_get_i64": (STATUS, [HANDLE, c_uint64, KEY, POINTER(c_int64)]),
    "sogmm_map_frame_get_f64": (STATUS, [HANDLE, c_uint64, KEY, POINTER(c_double)]),
    "sogmm_map_frame_get_pose": (STATUS, [HANDLE, c_uint64, F64_OUT]),
    "sogmm_map_get_origin": (STATUS, [HANDLE, F64_OUT]),
    "sogmm_map_set_origin": (STATUS, [HANDLE, F64_IN]),
    "sogmm_map_export": (STATUS, [HANDLE_OUT, HANDLE, c_void_p]),
    "sogmm_map_score_samples_f32": (STATUS, [HANDLE, F32_IN, c_size_t, c_int32, HANDLE, F64_OUT]),
    "sogmm_map_regress_gray_f32": (STATUS, [HANDLE, F32_IN, c_size_t, HANDLE, F32_OUT, F32_OUT]),
    "sogmm_map_sample_f32": (STATUS, [HANDLE, c_size_t, c_uint64, c_int32, HANDLE, F32_OUT]),
    # state_out and gradient_out may be NULL: c_void_p (None or arr.ctypes.data).
    "sogmm_map_occupancy_f32": (STATUS, [HANDLE, F32_IN, c_size_t, HANDLE, F64_OUT, c_void_p]),
    "sogmm_model_surface_distance_f32": (STATUS, [HANDLE, F32_IN, c_size_t, HANDLE, F64_OUT, c_void_p]),
    "sogmm_map_surface_distance_f32": (STATUS, [HANDLE, F32_IN, c_size_t, HANDLE, F64_OUT, c_void_p]),
    "sogmm_model_collision_probability": (STATUS, [HANDLE, F64_IN, F64_IN, c_size_t, HANDLE, F64_OUT]),
    "sogmm_map_collision_probability": (STATUS, [HANDLE, F64_IN, F64_IN, c_size_t, HANDLE, F64_OUT]),
    "sogmm_register_points_f32": (STATUS, [HANDLE, F32_IN, c_size_t, c_void_p, HANDLE, F64_OUT, c_void_p]),
    "sogmm_register_model": (STATUS, [HANDLE, HANDLE, c_void_p, HANDLE, F64_OUT, c_void_p]),
    "sogmm_model_render_f32": (STATUS, [HANDLE, c_uint32, c_uint32, c_double, c_double, c_double, c_double, F64_IN,
                                        HANDLE, F32_OUT, F32_OUT, F32_OUT]),
    "sogmm_map_render_f32": (STATUS, [HANDLE, c_uint32, c_uint32, c_double, c_double, c_double, c_double, F64_IN,
                                      HANDLE, F32_OUT, F32_OUT, F32_OUT]),
    "sogmm_map_save": (STATUS, [HANDLE, c_char_p, HANDLE]),
    "sogmm_map_load": (STATUS, [HANDLE_OUT, c_char_p, HANDLE]),
    "sogmm_map_export_delta": (STATUS, [HANDLE, c_uint64, HANDLE, c_void_p, c_size_t, POINTER(c_size_t)]),
    "sogmm_map_apply_delta": (STATUS, [HANDLE, c_void_p, c_size_t, HANDLE]),
    "sogmm_map_merge_map": (STATUS, [HANDLE, HANDLE, F64_IN, POINTER(c_uint64)]),
    "sogmm_trajectory_read": (STATUS, [HANDLE_OUT, c_char_p]),
    "sogmm_trajectory_free": (None, [HANDLE]),
    "sogmm_trajectory_size": (c_size_t, [HANDLE]),
    "sogmm_trajectory_poses": (c_void_p, [HANDLE]),
    "sogmm_trajectory_ids": (c_void_p, [HANDLE]),
    "sogmm_trajectory_write": (STATUS, [c_char_p, F64_IN, c_size_t]),
    "sogmm_buffer_data": (POINTER(c_uint8), [HANDLE]),
    "sogmm_buffer_size": (c_size_t, [HANDLE]),
    "sogmm_buffer_free": (None, [HANDLE]),
}

def _library_file_names() -> list[str]:
    if sys.platform == "win32":
        return ["sogmm.dll", "libsogmm.dll"]
    if sys.platform == "darwin":
        return ["libsogmm.dylib", f"libsogmm.{ABI_VERSION}.dylib"]
    return ["libsogmm.so", f"libsogmm.so.{ABI_VERSION}"]


def _is_sanitizer_build(build_dir: Path) -> bool:
    """True for a build directory configured with SOGMM_SANITIZE=ON.

    Loading an AddressSanitizer library into a normal Python aborts the
    process, so such build trees are never picked automatically."""
    if "asan" in build_dir.name.lower() or "sanit" in build_dir.name.lower():
        return True
    cache = build_dir / "CMakeCache.txt"
    try:
        text = cache.read_text(errors="replace")
    except OSError:
        return False
    for line in text.splitlines():
        if line.startswith("SOGMM_SANITIZE:") and line.split("=", 1)[-1].strip().upper() in ("ON", "1", "TRUE", "YES"):
            return True
    return False


def _checkout_candidates() -> list[Path]:
    """libsogmm files of the build trees of a source checkout, newest first."""
    here = Path(__file__).resolve()
    # <repo>/bindings/python/src/sogmm/_ffi.py
    for root in here.parents:
        if (root / "capi" / "include" / "sogmm" / "sogmm.h").is_file():
            break
    else:
        return []
    found = []
    for build_dir in root.glob("build*"):
        if not build_dir.is_dir() or _is_sanitizer_build(build_dir):
            continue
        for name in _library_file_names():
            f = build_dir / "capi" / name
            if f.is_file():
                found.append(f)
                break
    found.sort(key=lambda p: p.resolve().stat().st_mtime, reverse=True)
    return found


def _candidates() -> list[tuple[str, Path]]:
    env = os.environ.get("SOGMM_LIBRARY_PATH")
    if env:
        # An explicit choice is never silently replaced by another library.
        return [("SOGMM_LIBRARY_PATH", Path(env))]
    out: list[tuple[str, Path]] = []
    bundled = Path(__file__).resolve().parent / "_lib"
    for name in _library_file_names():
        if (bundled / name).is_file():
            out.append(("bundled", bundled / name))
            break
    out.extend(("build tree", p) for p in _checkout_candidates())
    return out


def _load() -> tuple[ctypes.CDLL, Path]:
    tried = []
    candidates = _candidates()
    for origin, path in candidates:
        if not path.is_file():
            tried.append(f"{origin}: {path} (no such file)")
            continue
        try:
            if sys.platform == "win32":  # pragma: no cover - not built on Windows yet
                os.add_dll_directory(str(path.parent))
            lib = ctypes.CDLL(str(path))
        except OSError as e:
            tried.append(f"{origin}: {path} ({e})")
            continue
        try:
            abi = lib.sogmm_abi_version
        except AttributeError:
            tried.append(f"{origin}: {path} (not libsogmm: no sogmm_abi_version)")
            continue
        abi.restype = c_uint32
        abi.argtypes = []
        found_abi = int(abi())
        if found_abi != ABI_VERSION:
            raise ImportError(
                f"sogmm: {path} ({origin}) has ABI version {found_abi}, but this package needs "
                f"ABI version {ABI_VERSION}; install a matching wheel or point SOGMM_LIBRARY_PATH "
                "at a matching libsogmm"
            )
        return lib, path
    detail = "; ".join(tried) if tried else "no bundled library and no build tree found"
    raise ImportError(
        "sogmm: cannot load the C library libsogmm (" + detail + "). Install the sogmm wheel, set "
        "SOGMM_LIBRARY_PATH to libsogmm.so, or build it in a checkout with "
        "'cmake --build <build-dir> --target sogmm'."
    )


lib, library_path = _load()

for _name, (_restype, _argtypes) in _DECLARATIONS.items():
    _fn = getattr(lib, _name)
    _fn.restype = _restype
    _fn.argtypes = _argtypes


def declarations() -> dict[str, tuple[object, list[object]]]:
    """The ctypes declarations (name -> (restype, argtypes)); used by tests."""
    return dict(_DECLARATIONS)


def last_error() -> str:
    return lib.sogmm_last_error().decode("utf-8", "replace")


def check(status: int) -> None:
    """Raise the SogmmError subclass for a non-zero status.

    Must be called right after the C call, on the same thread, so that
    sogmm_last_error() still describes that call."""
    if status != OK:
        message = last_error()
        if not message:
            message = lib.sogmm_status_string(status).decode("utf-8", "replace")
        raise error_for_status(int(status), message)


class OptionInfo(ctypes.Structure):
    """sogmm_option_info: what the library's option registry says of a key."""

    _fields_ = [
        ("struct_size", c_size_t),
        ("key", ctypes.c_int32),
        ("type", ctypes.c_int32),
        ("name", ctypes.c_char_p),
        ("default_f64", c_double),
        ("lower_f64", c_double),
        ("upper_f64", c_double),
        ("default_i64", c_int64),
        ("lower_i64", c_int64),
        ("upper_i64", c_int64),
        ("range", ctypes.c_char_p),
        ("unit", ctypes.c_char_p),
        ("doc", ctypes.c_char_p),
    ]


def option_info(key: int) -> OptionInfo:
    """The registry's row of an option key (sogmm_option_get_info)."""
    info = OptionInfo(struct_size=ctypes.sizeof(OptionInfo))
    check(lib.sogmm_option_get_info(key, ctypes.byref(info)))
    return info


def option_default(key: int):
    """The library's default of an option key: a float for f64 keys, an int for i64 keys."""
    info = option_info(key)
    return info.default_f64 if info.type == 0 else info.default_i64


def _option_defaults() -> types.SimpleNamespace:
    """Every option's library default, by its C name without SOGMM_OPT_, lower case
    (DEFAULTS.bandwidth, DEFAULTS.map_batch_size, ...): the package's keyword defaults."""
    count = c_size_t()
    check(lib.sogmm_option_keys(None, 0, ctypes.byref(count)))
    keys = (KEY * count.value)()
    check(lib.sogmm_option_keys(keys, count.value, ctypes.byref(count)))
    return types.SimpleNamespace(**{
        option_info(k).name.decode()[len("SOGMM_OPT_"):].lower(): option_default(k) for k in keys})


DEFAULTS = _option_defaults()


# Python-side names of the option keys (the C message names the C macro).
OPTION_NAMES = {
    OPT_BANDWIDTH: "bandwidth",
    OPT_N_COMPONENTS: "n_components",
    OPT_TOL: "tol",
    OPT_REG_COVAR: "reg_covar",
    OPT_MAX_ITER: "max_iter",
    OPT_SEED: "seed",
    OPT_THREADS: "n_threads",
    OPT_MODE_COUNTER: "mode_counter",
    OPT_TRUNCATION_NATS: "truncation_nats",
    OPT_N_INIT: "n_init",
    OPT_DEQUANTISE_DEPTH: "dequantise_depth",
    OPT_EM_ACCELERATION: "em_acceleration",
    OPT_TOL_STANDARD_ERRORS: "tol_standard_errors",
    OPT_WARM_MAX_ITER: "warm_max_iter",
    OPT_DEPTH_SCALE: "depth_scale",
    OPT_DEPTH_MIN: "depth_min",
    OPT_DEPTH_MAX: "depth_trunc",
    OPT_DECIMATION: "decimate",
    OPT_ZSTD_LEVEL: "zstd_level",
    OPT_FLOAT64: "float64",
    OPT_COMPRESS: "compress",
    OPT_ARRAY_PRECISION: "component_precision",
    OPT_MAX_DECODED_BYTES: "max_decoded_bytes",
    OPT_VERIFY_CHECKSUMS: "verify_checksums",
    OPT_SAMPLE_TRUNCATION: "truncation",
    OPT_QUERY_TRUNCATION_NATS: "truncation_nats",
    OPT_RENDER_SURFACE_SIGMA: "surface_sigma",
    OPT_MAP_NOVELTY: "novelty",
    OPT_MAP_NOVELTY_THRESHOLD: "novelty_threshold",
    OPT_MAP_NOVELTY_BANDWIDTH_SCALE: "novelty_bandwidth_scale",
    OPT_MAP_REVISIT_REFIT_RATIO: "revisit_refit_ratio",
    OPT_MAP_FREE_SPACE_CARVE: "free_space_carve",
    OPT_MAP_COMPONENT_PRECISION: "component_precision",
    OPT_MAP_BATCH_SIZE: "batch_size",
    OPT_MAP_FUSION: "fusion",
    OPT_MAP_FUSION_METHOD: "fusion",
    OPT_MAP_FUSION_THRESHOLD: "fusion_threshold",
    OPT_MAP_WARM_START: "warm_start",
    OPT_OCCUPANCY_SIGMA: "surface_sigma",
    OPT_OCCUPANCY_THICKNESS: "thickness",
    OPT_SURFACE_DISC_SIGMAS: "disc_sigmas",
    OPT_REGISTRATION_MAX_ITER: "max_iter",
    OPT_REGISTRATION_TOL: "tol",
    OPT_REGISTRATION_OUTLIER_RATIO: "outlier_ratio",
    OPT_REGISTRATION_USE_GRAY: "use_gray",
    OPT_REGISTRATION_LEVELS: "levels",
    OPT_REGISTRATION_COARSE_SIGMA: "coarse_sigma",
    OPT_REGISTRATION_MIN_INLIER_RATIO: "min_inlier_ratio",
    OPT_REGISTRATION_DEGENERACY_RATIO: "degeneracy_ratio",
    OPT_REGISTRATION_MIN_POINTS: "min_points",
}


def _check_option(status: int, key: int, value) -> None:
    """check() for an option setter; the message is prefixed with the parameter's name."""
    if status != OK:
        message = last_error() or lib.sogmm_status_string(status).decode("utf-8", "replace")
        name = OPTION_NAMES.get(key)
        if name is not None:
            message = f"{name} = {value!r} is invalid: {message}"
        raise error_for_status(int(status), message)


class Options:
    """Owns a sogmm_options handle for the duration of one call (a context manager)."""

    __slots__ = ("ptr",)

    def __init__(self, f64: dict[int, float] | None = None, i64: dict[int, int] | None = None):
        out = c_void_p()
        check(lib.sogmm_options_create(ctypes.byref(out)))
        self.ptr = out
        try:
            for key, value in (f64 or {}).items():
                _check_option(lib.sogmm_options_set_f64(self.ptr, key, float(value)), key, value)
            for key, value in (i64 or {}).items():
                _check_option(lib.sogmm_options_set_i64(self.ptr, key, int(value)), key, value)
        except BaseException:
            self.close()
            raise

    def close(self) -> None:
        if self.ptr:
            lib.sogmm_options_free(self.ptr)
            self.ptr = c_void_p()

    def __enter__(self) -> "Options":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def buffer_to_bytes(buf: c_void_p) -> bytes:
    """Copies a sogmm_buffer's bytes into a Python bytes object (does not free it)."""
    size = lib.sogmm_buffer_size(buf)
    if size == 0:
        return b""
    data = lib.sogmm_buffer_data(buf)
    return ctypes.string_at(data, size)
