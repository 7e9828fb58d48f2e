"""GMM.set_info (sogmm_model_set_info_f64/_i64): the fit record and camera of
a model rebuilt from arrays, round-tripped through a .sogmm file; refused
values name the key and leave the model unchanged."""

import math

import numpy as np
import pytest

import sogmm


def _model() -> sogmm.GMM:
    cov = np.tile(np.diag([0.01, 0.02, 0.03, 0.04]).astype(np.float32), (2, 1, 1))
    return sogmm.GMM.from_arrays([0.25, 0.75], np.arange(8, dtype=np.float32).reshape(2, 4), cov, support_size=40)


def test_a_model_from_arrays_gets_the_record_of_a_fit():
    """The record of a real fit, copied value by value onto a model built from
    its arrays, makes the same file metadata."""
    rng = np.random.default_rng(0)
    x = rng.normal(size=(400, 4)).astype(np.float32) * [0.3, 0.3, 0.3, 0.1] + [0, 0, 2, 0.5]
    fitted = sogmm.SOGMM(bandwidth=0.3, seed=4).fit(x)
    stored = {k: v for k, v in fitted.info().items()
              if k.startswith(("fit_", "camera_")) and not k.startswith(("fit_seconds", "fit_n_points", "fit_n_init",
                                                                          "fit_run"))}
    rebuilt = sogmm.GMM.from_arrays(fitted.weights_, fitted.means_, fitted.covariances_,
                                    support_size=fitted.support_size_)
    assert rebuilt.lower_bound_ is None
    rebuilt.set_info(**stored)
    back = sogmm.from_bytes(rebuilt.to_bytes())
    got = {k: v for k, v in back.info().items() if k in stored}
    assert got == stored and len(stored) == 9  # the 9 FitInfo fields of spec/format.md 4.2


def test_the_first_key_creates_the_record_with_the_format_defaults():
    m = _model()
    m.set_info(camera_decimation=5)
    back = sogmm.from_bytes(m.to_bytes()).info()
    assert back["camera_decimation"] == 5
    # spec/format.md 4.2 table Camera: 0 for the intrinsics, depth 1000 / 0.1 / 3.0
    assert (back["camera_width"], back["camera_fx"], back["camera_depth_scale"], back["camera_depth_min"],
            back["camera_depth_max"]) == (0, 0.0, 1000.0, 0.1, 3.0)
    assert "fit_bandwidth" not in back  # the other record is untouched


@pytest.mark.parametrize("values,match", [
    ({"fit_log_likelihood": math.nan}, "not finite"),
    ({"camera_fx": math.inf}, "not finite"),
    ({"fit_converged": 2}, "not 0 or 1"),
    ({"camera_decimation": 0}, "outside"),
    ({"fit_max_iter": 2**31}, "outside"),
    ({"fit_n_components_requested": -1}, "negative"),
    ({"support_size": 3}, "not stored"),
    ({"fit_seconds_em": 1.0}, "not stored"),
    ({"fit_run": 0}, "not stored"),
    ({"bandwidth": 0.1}, "unknown info name"),
])
def test_refused_values_leave_the_model_unchanged(values, match):
    m = _model()
    before = m.to_bytes()
    with pytest.raises(sogmm.InvalidArgumentError, match=match):
        m.set_info(**values)
    assert m.info() == sogmm.from_bytes(before).info() | {"created_unix_ms": m.info()["created_unix_ms"]}
    assert m.lower_bound_ is None and m.camera_ is None
