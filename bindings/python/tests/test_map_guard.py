"""A Map used from two threads or from its own progress callback raises
MapBusyError instead of crashing (issue 36: close() or insert_points() from
the callback segfaulted, close() from another thread aborted with a double
free), and Ctrl-C raises a plain KeyboardInterrupt only when the call was
really cancelled: a call that completed keeps its result (issue 36: a map
insert committed the frame, a fit leaked its model)."""

from __future__ import annotations

import signal
import threading

import numpy as np
import pytest

import sogmm
from sogmm import _ffi

from conftest import blobs, synthetic_rgbd

FIT = dict(bandwidth=0.08, seed=3, n_threads=1)


def fitting_map() -> sogmm.Map:
    """A map whose first insert of blobs() runs a fit (so it calls the callback)."""
    return sogmm.Map(batch_size=500, **FIT)


def test_callback_calling_close_or_insert_raises_map_busy():
    pts = blobs()
    for nested in ("close", "insert_points", "flush", "stats", "score_samples"):
        with fitting_map() as m:
            seen = []

            def callback(stage, step, total, ll, m=m, nested=nested):
                if not seen:
                    seen.append(nested)
                    if nested == "close":
                        m.close()
                    elif nested == "insert_points":
                        m.insert_points(pts, np.eye(4))
                    elif nested == "flush":
                        m.flush()
                    elif nested == "stats":
                        m.stats()
                    else:
                        m.score_samples(pts[:10])
                return False

            # The callback's exception cancels the insert and is re-raised.
            with pytest.raises(sogmm.MapBusyError, match=r"^map busy: Map\.\w+ cannot run") as e:
                m.insert_points(pts, np.eye(4), progress=callback)
            assert e.value.status == -13
            # The map is open, unchanged (the insert was cancelled) and usable.
            assert len(m) == 0 and m.n_components_ == 0
            m.insert_points(pts, np.eye(4))
            assert len(m) == 1 and m.n_components_ > 0


def test_a_second_thread_gets_map_busy_while_an_insert_runs():
    pts = blobs()
    m = fitting_map()
    inside, tried = threading.Event(), threading.Event()
    errors = {}

    def hold(stage, step, total, ll):
        inside.set()
        tried.wait()  # thread B's calls happen while this insert runs
        return False

    def thread_b():
        inside.wait()
        for name, call in (("close", m.close), ("insert_points", lambda: m.insert_points(pts, np.eye(4))),
                           ("frame_stats", lambda: m.stats()), ("export", m.export)):
            try:
                call()
                errors[name] = None
            except sogmm.MapBusyError as e:
                errors[name] = str(e)
        tried.set()

    b = threading.Thread(target=thread_b)
    b.start()
    m.insert_points(pts, np.eye(4), progress=hold)
    b.join()
    assert all(msg is not None and msg.startswith("map busy: ") for msg in errors.values()), errors
    assert len(m) == 1 and m.n_components_ > 0  # thread A's insert alone went in
    m.close()
    with pytest.raises(sogmm.InvalidArgumentError, match="closed"):
        m.stats()


def test_threads_inserting_at_once_never_corrupt_the_map():
    # Each insert either goes in whole or raises MapBusyError; the map then
    # holds exactly the inserts that succeeded (before: wrong counts, a
    # valid pose rejected, memory corrupted).
    pts = blobs(n_per=100)
    m = sogmm.Map(novelty=False, batch_size=100000, **FIT)  # every insert adds its points
    done = []
    lock = threading.Lock()

    def worker():
        for _ in range(20):
            try:
                m.insert_points(pts, np.eye(4))
                with lock:
                    done.append(1)
            except sogmm.MapBusyError:
                pass

    threads = [threading.Thread(target=worker) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    with sogmm.Map(novelty=False, batch_size=100000, **FIT) as one:
        one.insert_points(pts, np.eye(4))
        per_frame = one.n_components_
    assert len(m) == len(done) >= 1
    assert m.n_components_ == len(done) * per_frame and m.n_pending_ == 0
    m.close()


# ---- Ctrl-C -------------------------------------------------------------------

needs_sigint = pytest.mark.skipif(
    threading.current_thread() is not threading.main_thread()
    or signal.getsignal(signal.SIGINT) is not signal.default_int_handler,
    reason="needs the default SIGINT handler on the main thread")


def interrupt_during(monkeypatch, name, after_last_report=False):
    """Makes C function `name` see a Ctrl-C that arrives while it runs, too
    late for a progress report to cancel it: SIGINT is raised (and handled by
    the binding's recording handler) just before the real call (it makes no
    report), or just after it (the signal came after its last report)."""
    real = getattr(_ffi.lib, name)

    def late_interrupt(*args):
        if not after_last_report:
            signal.raise_signal(signal.SIGINT)
        status = real(*args)
        if after_last_report:
            signal.raise_signal(signal.SIGINT)
        return status

    monkeypatch.setattr(_ffi.lib, name, late_interrupt)


@needs_sigint
def test_ctrl_c_during_an_insert_that_completes_keeps_the_frame(monkeypatch):
    depth, color, cam = synthetic_rgbd()
    with sogmm.Map(**FIT) as m:  # default batch: this insert runs no fit, so no report
        interrupt_during(monkeypatch, "sogmm_map_insert_frame")
        with pytest.raises(KeyboardInterrupt) as e:
            m.insert_rgbd(depth, color, cam, np.eye(4), progress=lambda *a: False)
        monkeypatch.undo()
        assert getattr(e.value, "sogmm_completed", False) is True  # not "cancelled": the frame is in
        assert len(m) == 1 and m.n_pending_ > 0


@needs_sigint
def test_ctrl_c_during_a_fit_that_completes_keeps_the_model(monkeypatch):
    pts = blobs()
    est = sogmm.SOGMM(n_components=4, seed=1, max_iter=5)
    interrupt_during(monkeypatch, "sogmm_fit_points_f32", after_last_report=True)
    with pytest.raises(KeyboardInterrupt) as e:
        est.fit(pts, progress=lambda *a: False)
    monkeypatch.undo()
    assert getattr(e.value, "sogmm_completed", False) is True
    # The model the C fit returned is attached (before: never attached nor freed).
    assert est.n_components_ == 4
    ref = sogmm.SOGMM(n_components=4, seed=1, max_iter=5).fit(pts)
    np.testing.assert_array_equal(est.means_, ref.means_)


@needs_sigint
def test_ctrl_c_seen_by_a_report_cancels_and_changes_nothing():
    pts = blobs()
    with fitting_map() as m:
        def ctrl_c(*a):
            signal.raise_signal(signal.SIGINT)  # recorded; this report cancels
            return False

        with pytest.raises(KeyboardInterrupt) as e:
            m.insert_points(pts, np.eye(4), progress=ctrl_c)
        assert not hasattr(e.value, "sogmm_completed")
        assert len(m) == 0 and m.n_components_ == 0
