"""Checked conversion of the arrays a caller passes (shared by GMM, Map and
the queries of :class:`sogmm.queryable.Queryable`)."""

from __future__ import annotations

import secrets

import numpy as np

from .errors import InvalidArgumentError


def _real_array(x, dtype, name: str) -> np.ndarray:
    try:
        a = np.asarray(x)
    except (TypeError, ValueError) as e:
        raise InvalidArgumentError(f"{name} must be a numeric array ({e})") from None
    if a.dtype.kind not in "biuf":
        raise InvalidArgumentError(f"{name} must hold real numbers, got dtype {a.dtype}")
    return np.ascontiguousarray(a, dtype=dtype)


def _rows(x, cols: tuple[int, ...], name: str) -> np.ndarray:
    a = _real_array(x, np.float32, name)
    if a.ndim != 2 or a.shape[1] not in cols:
        want = " or ".join(str(c) for c in cols)
        raise InvalidArgumentError(f"{name} must be a 2-D array with {want} columns, got shape {a.shape}")
    return a


def _pose(pose) -> np.ndarray:
    p = _real_array(pose, np.float64, "pose")
    if p.shape != (4, 4):
        raise InvalidArgumentError(f"pose must be a 4 x 4 matrix, got shape {p.shape}")
    return p


def _count(n, name: str) -> int:
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 0:
        raise InvalidArgumentError(f"{name} must be a non-negative integer, got {n!r}")
    return int(n)


def _sample_args(n_samples, seed, spatial_only: bool) -> tuple[int, int, int, np.ndarray]:
    """Checked (n, seed as uint64 bits, dims, output array) of a sample call;
    seed=None draws a fresh seed."""
    n = _count(n_samples, "n_samples")
    if seed is None:
        seed = secrets.randbits(64)
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)):
        raise InvalidArgumentError(f"seed must be an int, got {seed!r}")
    dims = 3 if spatial_only else 4
    return n, int(seed) & 0xFFFFFFFFFFFFFFFF, dims, np.empty((n, dims), dtype=np.float32)
