"""Independent models used from several Python threads; the GIL is released in C."""

from __future__ import annotations

import threading
import time
from concurrent.futures import ThreadPoolExecutor

import numpy as np

import sogmm

from conftest import blobs


def _fit(seed: int):
    x = blobs(n_per=300, seed=seed)
    m = sogmm.SOGMM(bandwidth=0.08, seed=seed, n_threads=1).fit(x)
    return m.weights_.copy(), m.means_.copy(), m.covariances_.copy(), m.score_samples(x)


def test_independent_models_in_threads_match_serial():
    seeds = list(range(8))
    serial = [_fit(s) for s in seeds]
    with ThreadPoolExecutor(max_workers=4) as pool:
        parallel = list(pool.map(_fit, seeds))
    for s, p in zip(serial, parallel):
        for a, b in zip(s, p):
            np.testing.assert_array_equal(a, b)


def test_shared_model_const_queries_in_threads(fitted, points):
    expected_scores = fitted.score_samples(points)
    expected_samples = fitted.sample(5000, seed=3)
    expected_gray = fitted.regress_gray(points[:, :3])

    def work(_):
        for _ in range(5):
            np.testing.assert_array_equal(fitted.score_samples(points), expected_scores)
            np.testing.assert_array_equal(fitted.sample(5000, seed=3), expected_samples)
            m, v = fitted.regress_gray(points[:, :3])
            np.testing.assert_array_equal(m, expected_gray[0])
            np.testing.assert_array_equal(v, expected_gray[1])
        return True

    with ThreadPoolExecutor(max_workers=4) as pool:
        assert all(pool.map(work, range(8)))


def test_error_messages_are_per_thread():
    """Threads failing in different ways at the same time each see their own message."""
    x = blobs(n_per=20)
    bad = x.copy()
    bad[3, 1] = np.nan
    barrier = threading.Barrier(4)

    def fail(kind: int) -> str:
        barrier.wait()
        for _ in range(50):
            try:
                if kind == 0:
                    sogmm.SOGMM(bandwidth=-1.0).fit(x)
                elif kind == 1:
                    sogmm.SOGMM().fit(bad)
                elif kind == 2:
                    sogmm.load("/nonexistent/dir/model.sogmm")
                else:
                    sogmm.from_bytes(b"not a model at all")
            except sogmm.SogmmError as e:
                msg = type(e).__name__ + ":" + e.message
            else:
                raise AssertionError("no error")
            if kind == 0:
                assert msg.startswith("InvalidArgumentError:") and "bandwidth" in msg.lower(), msg
            elif kind == 1:
                assert msg.startswith("InvalidDataError:"), msg
            elif kind == 2:
                assert msg.startswith("SogmmIOError:"), msg
            else:
                assert msg.startswith("FormatError:"), msg
        return msg

    with ThreadPoolExecutor(max_workers=4) as pool:
        msgs = list(pool.map(fail, range(4)))
    assert len(set(msgs)) == 4


def test_gil_is_released_during_a_fit():
    x = blobs(n_per=2000, seed=1, scale=0.05)
    done = threading.Event()
    result = {}

    def fit():
        t0 = time.perf_counter()
        result["m"] = sogmm.SOGMM(bandwidth=0.03, n_threads=1).fit(x)
        result["seconds"] = time.perf_counter() - t0
        done.set()

    t = threading.Thread(target=fit)
    ticks = 0
    t.start()
    while not done.is_set():
        ticks += 1  # runs only while the fit thread does not hold the GIL
        time.sleep(0.001)
    t.join()
    assert result["m"].n_components_ >= 1
    # With the GIL held for the whole fit the loop would tick only once or twice.
    if result["seconds"] > 0.1:
        assert ticks >= 10, (ticks, result["seconds"])
