"""save / to_bytes keep to the reader's decoded-size cap: max_decoded_bytes
below a model's array bytes (2 components: 2 x 15 float32 = 120 bytes)
raises LimitError naming the cap and writes nothing; the same cap on both
sides round-trips."""

import numpy as np
import pytest

import sogmm


def _model() -> sogmm.GMM:
    cov = np.tile(np.diag([0.01, 0.02, 0.03, 0.04]).astype(np.float32), (2, 1, 1))
    return sogmm.GMM.from_arrays([0.25, 0.75], np.arange(8, dtype=np.float32).reshape(2, 4), cov, support_size=40)


def test_save_above_the_cap_is_refused_and_writes_nothing(tmp_path):
    m = _model()
    path = tmp_path / "m.sogmm"
    with pytest.raises(sogmm.LimitError, match="120 bytes, over the cap of 119 bytes.*SOGMM_OPT_MAX_DECODED_BYTES"):
        m.save(path, max_decoded_bytes=119)
    assert list(tmp_path.iterdir()) == []
    with pytest.raises(sogmm.LimitError):
        m.to_bytes(max_decoded_bytes=119)
    with pytest.raises(sogmm.LimitError):
        m.to_bytes(float64=True, max_decoded_bytes=239)  # float64 doubles it
    m.save(path, max_decoded_bytes=120)
    back = sogmm.load(path, max_decoded_bytes=120)
    assert back.means_.tobytes() == m.means_.tobytes()
    assert len(m.to_bytes(float64=True, max_decoded_bytes=240)) > 0
