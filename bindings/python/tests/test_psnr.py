"""sogmm.psnr_images (sogmm_psnr_images_f32) against hand-computed values.

Pixel values and the error e = 1/8 are exact in float32, so the figures are
closed forms: a constant error e gives 10 log10(R^2 / e^2), and range 2 adds
exactly 20 log10 2 to range 1."""

import math

import numpy as np
import pytest

import sogmm

TRUTH = np.array([[0.25, 0.5], [-1.0, 0.75]], dtype=np.float32)  # one empty pixel (-1)
E = 0.125
ESTIMATE = np.where(TRUTH >= 0, TRUTH + E, -1.0).astype(np.float32)


def test_constant_error_gives_the_closed_form():
    r = sogmm.psnr_images(TRUTH, ESTIMATE)
    assert r.psnr == pytest.approx(10 * math.log10(1 / E**2), abs=1e-12)  # 18.06 dB
    # Paper figure: range 2, all 4 pixels counted, the empty one as perfect.
    assert r.psnr_paper == pytest.approx(10 * math.log10(4 / (3 * E**2 / 4)), abs=1e-12)


def test_range_two_adds_twenty_log10_two():
    one, two = sogmm.psnr_images(TRUTH, ESTIMATE, 1.0), sogmm.psnr_images(TRUTH, ESTIMATE, data_range=2.0)
    assert two.psnr - one.psnr == pytest.approx(20 * math.log10(2), abs=1e-12)
    assert two.psnr_paper == one.psnr_paper  # the paper figure ignores data_range


def test_range_zero_is_the_valid_truth_range():
    # valid truth pixels span 0.25 .. 0.75: range 0.5
    auto = sogmm.psnr_images(TRUTH, ESTIMATE, data_range=0)
    assert auto.psnr == pytest.approx(10 * math.log10(0.5**2 / E**2), abs=1e-12)


def test_identical_images_are_infinite_and_shapes_are_flattened():
    r = sogmm.psnr_images(TRUTH, TRUTH)
    assert r.psnr == math.inf and r.psnr_paper == math.inf
    flat = sogmm.psnr_images(TRUTH.ravel(), ESTIMATE.ravel())
    assert flat == sogmm.psnr_images(TRUTH, ESTIMATE)
    assert isinstance(flat, sogmm.PSNR) and flat.psnr == flat[0]


@pytest.mark.parametrize("estimate", [ESTIMATE.ravel(), ESTIMATE[:, :1], np.zeros(5, np.float32)])
def test_mismatched_shapes_are_refused(estimate):
    with pytest.raises(sogmm.InvalidArgumentError, match="same shape"):
        sogmm.psnr_images(TRUTH, estimate)


@pytest.mark.parametrize("data_range", [-1.0, -1e-300, math.nan, math.inf])
def test_negative_or_non_finite_range_is_refused(data_range):
    with pytest.raises(sogmm.InvalidArgumentError, match="data range"):
        sogmm.psnr_images(TRUTH, ESTIMATE, data_range)


def test_bad_pixels_are_refused():
    with pytest.raises(sogmm.InvalidArgumentError, match="data_range must be a number"):
        sogmm.psnr_images(TRUTH, ESTIMATE, "one")
    with pytest.raises(sogmm.InvalidArgumentError, match="real numbers"):
        sogmm.psnr_images(TRUTH.astype(str), ESTIMATE)
    with pytest.raises(sogmm.InvalidDataError):
        sogmm.psnr_images(np.full(4, -1, np.float32), np.zeros(4, np.float32))  # no valid truth pixel
    bad = ESTIMATE.copy()
    bad[0, 0] = np.nan
    with pytest.raises(sogmm.InvalidDataError):
        sogmm.psnr_images(TRUTH, bad)
    with pytest.raises(sogmm.InvalidDataError, match="constant"):
        sogmm.psnr_images(np.full(4, 0.5, np.float32), np.full(4, 0.25, np.float32), 0)
