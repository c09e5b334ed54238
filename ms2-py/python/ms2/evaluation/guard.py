"""Calling a solution's policy safely: per-call time limits and action checks.

Every way a policy can fail an episode becomes a :class:`PolicyFailure` with a ``kind`` (one of
:data:`FAILURE_KINDS`) and a human-readable ``reason``; the evaluator records it for that episode
and goes on with the next one.

Time limits: with a limit, :class:`PolicyCaller` runs each call in a worker thread and waits at
most the limit for it. Python cannot stop a thread, so a call that overruns is *abandoned*: its
thread (a daemon thread) runs on in the background until the call returns, its result is thrown
away, and the caller starts a fresh worker thread for the next call (the evaluator also builds a
fresh policy object, since the abandoned call may still be changing the old one). A call that
never returns keeps its thread, and the CPU time it burns, until the process exits; the process
does not wait for it. Without a limit (``None``) calls run directly in the calling thread.
"""

from __future__ import annotations

import queue
import threading
import time
from collections.abc import Callable
from typing import Any

import numpy as np
from gymnasium import spaces

#: Failure kinds and what each means.
FAILURE_KINDS = {
    "exception": "a policy method (act, reset) raised an exception",
    "invalid_action": "act() returned something that is not a real-valued array of the "
    "action space's shape",
    "non_finite_action": "act() returned an action with NaN or infinite elements",
    "timeout": "a policy method did not return within the per-step time limit",
    "env_error": "the env failed to reset or step (e.g. a bad reset option in the config)",
}

#: Longest exception message kept in a reason (longer ones are cut with "...").
MAX_MESSAGE_CHARS = 500


class PolicyFailure(Exception):
    """An episode's failure: ``kind`` (a key of :data:`FAILURE_KINDS`) and ``reason``."""

    def __init__(self, kind: str, reason: str) -> None:
        if kind not in FAILURE_KINDS:
            raise ValueError(f"unknown failure kind {kind!r}; valid: {list(FAILURE_KINDS)}")
        super().__init__(reason)
        self.kind = kind
        self.reason = reason


def describe_exception(err: BaseException) -> str:
    """``"TypeName: message"`` with the message cut to :data:`MAX_MESSAGE_CHARS`."""
    message = str(err)
    if len(message) > MAX_MESSAGE_CHARS:
        message = message[:MAX_MESSAGE_CHARS] + "..."
    return f"{type(err).__name__}: {message}" if message else type(err).__name__


class _Call:
    """One call handed to the worker thread, and its outcome."""

    def __init__(self, fn: Callable[..., Any], args: tuple[Any, ...]) -> None:
        self.fn = fn
        self.args = args
        self.done = threading.Event()
        self.result: Any = None
        self.error: BaseException | None = None

    def run(self) -> None:
        try:
            self.result = self.fn(*self.args)
        except BaseException as err:  # noqa: BLE001 - reported to the caller as a failure
            self.error = err
        finally:
            self.done.set()


class _Worker:
    """A daemon thread running :class:`_Call` objects one at a time."""

    def __init__(self) -> None:
        self._calls: queue.SimpleQueue[_Call | None] = queue.SimpleQueue()
        self.thread = threading.Thread(target=self._loop, name="ms2-eval-policy", daemon=True)
        self.thread.start()

    def _loop(self) -> None:
        while True:
            call = self._calls.get()
            if call is None:
                return
            call.run()

    def submit(self, call: _Call) -> None:
        self._calls.put(call)

    def stop(self) -> None:
        """Ends the thread once its current call (if any) returns."""
        self._calls.put(None)


class PolicyCaller:
    """Calls policy methods with an optional wall-time limit per call (seconds).

    :meth:`call` returns the method's result or raises :class:`PolicyFailure` (``exception``
    or ``timeout``). After a timeout :attr:`abandoned` counts the calls left running.
    """

    def __init__(self, time_limit: float | None) -> None:
        if time_limit is not None:
            if isinstance(time_limit, bool) or not isinstance(time_limit, (int, float)):
                raise TypeError(f"time limit must be a number of seconds, got {time_limit!r}")
            if not (time_limit > 0 and np.isfinite(time_limit)):
                raise ValueError(
                    f"time limit must be a positive number of seconds, got {time_limit}"
                )
        self.time_limit = time_limit
        self.abandoned = 0
        self._worker: _Worker | None = None

    def call(self, what: str, fn: Callable[..., Any], *args: Any) -> Any:
        """``fn(*args)``, named ``what`` (e.g. ``"act(obs)"``) in failure reasons."""
        if self.time_limit is None:
            try:
                return fn(*args)
            except (Exception, SystemExit) as err:
                raise PolicyFailure(
                    "exception", f"{what} raised {describe_exception(err)}"
                ) from err
        if self._worker is None:
            self._worker = _Worker()
        call = _Call(fn, args)
        started = time.perf_counter()
        self._worker.submit(call)
        if not call.done.wait(self.time_limit):
            self._worker.stop()  # the thread ends if the call ever returns
            self._worker = None
            self.abandoned += 1
            raise PolicyFailure(
                "timeout",
                f"{what} did not return within the per-step time limit of {self.time_limit:g} s "
                f"(abandoned after {time.perf_counter() - started:.2f} s)",
            )
        if call.error is not None:
            if isinstance(call.error, KeyboardInterrupt):
                raise call.error
            raise PolicyFailure(
                "exception", f"{what} raised {describe_exception(call.error)}"
            ) from call.error
        return call.result

    def close(self) -> None:
        """Ends the worker thread (an abandoned call's thread ends when its call returns)."""
        if self._worker is not None:
            self._worker.stop()
            self._worker = None


def check_action(action: Any, space: spaces.Space) -> np.ndarray:
    """``action`` as the float32 array the env steps with, or :class:`PolicyFailure`:
    ``invalid_action`` for anything that is not real numbers of ``space``'s shape,
    ``non_finite_action`` for NaN / inf elements (also values beyond float32's range).

    Values outside the space's bounds pass unchanged, as in ManiSkill2's evaluation: the
    normalized controllers clip them."""
    shape = space.shape
    if action is None:
        raise PolicyFailure(
            "invalid_action", f"act() returned None; expected float32 of shape {shape}"
        )
    try:
        array = np.asarray(action)
    except Exception as err:  # noqa: BLE001 - an arbitrary object's __array__ may raise anything
        raise PolicyFailure(
            "invalid_action",
            f"act() returned {type(action).__name__}, which is not convertible to an array "
            f"({describe_exception(err)}); expected float32 of shape {shape}",
        ) from err
    if array.dtype.kind not in "biuf":
        raise PolicyFailure(
            "invalid_action",
            f"act() returned {type(action).__name__} of dtype {array.dtype}; expected real "
            f"numbers (float32) of shape {shape}",
        )
    if array.shape != shape:
        raise PolicyFailure(
            "invalid_action", f"act() returned an action of shape {array.shape}, expected {shape}"
        )
    with np.errstate(over="ignore"):
        action32 = np.ascontiguousarray(array, dtype=np.float32)
    bad = np.flatnonzero(~np.isfinite(action32))
    if bad.size:
        shown = ", ".join(f"{action32.flat[i]} at index {i}" for i in bad[:3])
        more = f" and {bad.size - 3} more" if bad.size > 3 else ""
        raise PolicyFailure(
            "non_finite_action", f"act() returned a non-finite action: {shown}{more}"
        )
    return action32


__all__ = ["FAILURE_KINDS", "PolicyCaller", "PolicyFailure", "check_action", "describe_exception"]
