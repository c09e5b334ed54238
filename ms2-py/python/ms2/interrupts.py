"""Ctrl-C that cannot be lost: the ``ms2`` command line records every SIGINT before raising
``KeyboardInterrupt``, and long loops (demo generation, replays) check the record between
chunks. Python drops an exception raised where it cannot propagate (a finalizer, a callback run
by a C library), so without the record an interrupt landing there would let the run go on to
the end and exit 0."""

from __future__ import annotations

import signal
import threading
from types import FrameType

_requested = threading.Event()


def _on_sigint(signum: int, frame: FrameType | None) -> None:
    _requested.set()
    raise KeyboardInterrupt


def install() -> None:
    """Records SIGINT (then raises ``KeyboardInterrupt`` as Python's default handler does).
    Only from the main thread; a no-op elsewhere."""
    if threading.current_thread() is threading.main_thread():
        signal.signal(signal.SIGINT, _on_sigint)


def clear() -> None:
    """Forgets a recorded SIGINT (for an interactive session that goes on after one)."""
    _requested.clear()


def check() -> None:
    """Raises ``KeyboardInterrupt`` if a SIGINT was recorded (see :func:`install`)."""
    if _requested.is_set():
        raise KeyboardInterrupt


__all__ = ["check", "clear", "install"]
