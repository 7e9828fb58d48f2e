"""Progress reports and cancellation of long C calls (sogmm_progress_fn).

The library calls the progress callback only on the thread that made the
call, during the call, about every 20 ms. That makes it the point where Python
can act while C runs: a callable may cancel (truthy return), an exception in
it cancels and is re-raised after the call, and Ctrl-C cancels the fit and
raises KeyboardInterrupt.

Ctrl-C: Python runs signal handlers only on the main thread, between bytecodes,
so during a C call nothing happens until the callback runs Python code. On the
main thread, while the default handler is active, the call installs a handler
that only records SIGINT; the callback sees the record and cancels, and
KeyboardInterrupt is raised once the library has returned (cleanly, with
nothing allocated left behind). Elsewhere, an exception the current handler
raises inside the callback is caught and re-raised the same way.

A Ctrl-C that comes too late to cancel (after the last report, or during a
call that makes none, such as a map insert that runs no fit) finds the call
completed: its result is kept (the fitted model attached, the frame in the
map) and KeyboardInterrupt is raised after it, as Python does after a C call
that finished, with ``sogmm_completed = True`` and a note saying so. Only a
KeyboardInterrupt without that attribute means the call was cancelled and
changed nothing.
"""
from __future__ import annotations

import signal
import threading
from typing import Callable, Optional, Union

from . import _ffi
from ._ffi import check, lib

#: Stage numbers of sogmm.h (SOGMM_STAGE_*) and their names.
STAGE_MODE_COUNT = 1
STAGE_SEEDING = 2
STAGE_EM = 3
STAGE_RUN = 4
STAGE_SAMPLING = 5
STAGE_SCORING = 6
STAGE_REGRESSION = 7
STAGE_RENDERING = 8
STAGE_REGISTRATION = 9
STAGE_NAMES = {
    STAGE_MODE_COUNT: "mode count",
    STAGE_SEEDING: "seeding",
    STAGE_EM: "EM",
    STAGE_RUN: "run",
    STAGE_SAMPLING: "sampling",
    STAGE_SCORING: "scoring",
    STAGE_REGRESSION: "gray regression",
    STAGE_RENDERING: "rendering",
    STAGE_REGISTRATION: "registration",
}

#: progress= accepts None, True (a tqdm bar) or callable(stage, step, total, log_likelihood) -> truthy cancels.
ProgressArg = Union[None, bool, Callable[[int, int, int, float], object]]


class _TqdmSink:
    """One tqdm bar per stage: step of total, the EM log-likelihood as postfix."""

    def __init__(self):
        try:
            from tqdm.auto import tqdm
        except ImportError as e:
            raise ImportError("progress=True needs tqdm, the extra `progress`: pip install 'sogmm[progress]'") from e
        self._tqdm = tqdm
        self._bar = None
        self._stage = None

    def __call__(self, stage: int, step: int, total: int, log_likelihood: float) -> bool:
        if stage != self._stage or self._bar is None:
            self.close()
            self._stage = stage
            self._bar = self._tqdm(total=total or None, desc=STAGE_NAMES.get(stage, f"stage {stage}"),
                                   leave=False)
        if step > self._bar.n:
            self._bar.update(step - self._bar.n)
        if stage == STAGE_EM and step > 0:
            self._bar.set_postfix(loglik=f"{log_likelihood:.4f}", refresh=False)
        return False

    def close(self) -> None:
        if self._bar is not None:
            self._bar.close()
            self._bar = None


def _sink(progress: ProgressArg):
    if progress is None or progress is False:
        return None
    if progress is True:
        return _TqdmSink()
    if callable(progress):
        return progress
    raise TypeError(f"progress must be None, True or a callable(stage, step, total, log_likelihood), got {progress!r}")


def _interrupt_after_completed_call() -> KeyboardInterrupt:
    e = KeyboardInterrupt()
    e.sogmm_completed = True
    note = "sogmm: the call had completed when Ctrl-C was seen; its result was kept"
    if hasattr(e, "add_note"):  # Python >= 3.11
        e.add_note(note)
    return e


def call_with_progress(options: Optional[_ffi.Options], progress: ProgressArg, c_call: Callable[[], int], *,
                       install: Optional[Callable[[object], int]] = None,
                       keep: Optional[Callable[[], None]] = None) -> None:
    """Runs ``c_call()`` (one C call using ``options``, returning its status)
    with the progress callback set on ``options``; raises what the call or the
    callback raised, KeyboardInterrupt on Ctrl-C, CancelledError when the
    callable returned a truthy value. ``install(callback)`` replaces setting it
    on ``options`` (a map's inserts: sogmm_map_set_progress); it is called
    again with a NULL PROGRESS_FN after the call to remove the callback.
    ``keep()`` runs when the C call succeeded, before anything is raised: it
    takes what the call made (a model handle), so a call that completed is
    never lost to a late Ctrl-C or callback exception."""
    sink = _sink(progress)
    state = {"error": None, "sigint": False}

    def callback(stage, step, total, log_likelihood, _user_data):
        try:
            if state["error"] is None and not state["sigint"] and sink is not None:
                if sink(int(stage), int(step), int(total), float(log_likelihood)):
                    return 1
        except BaseException as e:  # KeyboardInterrupt too: never let it unwind into C
            state["error"] = e
        # Checked last: a SIGINT handled while this function ran counts now.
        return 1 if state["error"] is not None or state["sigint"] else 0

    c_callback = _ffi.PROGRESS_FN(callback)  # kept alive by this frame during the call
    if install is None:
        check(lib.sogmm_options_set_progress(options.ptr, c_callback, None))
    else:
        check(install(c_callback))
    previous = None
    if threading.current_thread() is threading.main_thread() and \
            signal.getsignal(signal.SIGINT) is signal.default_int_handler:
        def on_sigint(signum, frame):
            state["sigint"] = True

        previous = signal.signal(signal.SIGINT, on_sigint)
    try:
        status = c_call()
    finally:
        if install is not None:
            install(_ffi.PROGRESS_FN())  # NULL: the handle must not keep a callback that dies with this frame
        if previous is not None:
            signal.signal(signal.SIGINT, previous)
        if isinstance(sink, _TqdmSink):
            sink.close()
    if status == _ffi.OK and keep is not None:
        keep()
    if state["error"] is not None:
        raise state["error"]
    if state["sigint"]:
        raise _interrupt_after_completed_call() if status == _ffi.OK else KeyboardInterrupt
    check(status)
