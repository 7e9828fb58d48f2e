"""Image metrics: the PSNR of a gray image against the frame's (sogmm_psnr_images_f32)."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ._ffi import check, lib
from .errors import InvalidArgumentError
from .model import _real_array

__all__ = ["PSNR", "psnr_images"]


class PSNR(NamedTuple):
    """Both figures of :func:`psnr_images`, in dB (+inf for identical images)."""

    #: 10 log10(data_range^2 / MSE) over the pixels valid in the truth (>= 0).
    psnr: float
    #: The authors' evaluation: range 2, every pixel counted (empty ones as perfect).
    psnr_paper: float


def psnr_images(truth, estimate, data_range: float = 1.0) -> PSNR:
    """PSNR of the gray image ``estimate`` against ``truth``: two arrays of the
    same shape (any, e.g. H x W), where -1 marks an empty pixel, as ``sogmm
    eval`` draws a rendering of the model against the frame's gray.

    ``data_range`` is the peak: 1 for gray in [0, 1], any other peak for other
    data, or 0 for the actual range of the valid truth pixels (max - min).
    Shapes that differ or a non-numeric array raise InvalidArgumentError; a
    negative or non-finite ``data_range`` raises InvalidArgumentError (from the
    library, naming it); NaN/Inf pixels, a truth without a valid pixel, or
    ``data_range`` 0 on a constant truth not matched exactly raise
    InvalidDataError."""
    t = _real_array(truth, np.float32, "truth")
    e = _real_array(estimate, np.float32, "estimate")
    if t.shape != e.shape:
        raise InvalidArgumentError(f"truth and estimate must have the same shape, got {t.shape} and {e.shape}")
    try:
        r = float(data_range)
    except (TypeError, ValueError):
        raise InvalidArgumentError(f"data_range must be a number, got {data_range!r}") from None
    out = np.empty(2, dtype=np.float64)
    check(lib.sogmm_psnr_images_f32(t.ravel(), e.ravel(), t.size, r, out[:1], out[1:]))
    return PSNR(float(out[0]), float(out[1]))
