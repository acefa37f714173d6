"""Stop a long-running program (the server, a component) on SIGTERM or Ctrl-C without raising from the
signal handler.

The handler only notes the signal, and the program's wait polls the note. A handler that raised, or
that set a ``threading.Event``, could act at any bytecode of the main thread: while the handler was
being installed (the exception escaped the code meant to catch it, skipping the stop hooks), or while
the main thread held the very lock the handler needed (``Event.wait`` holds its condition's lock
between its timeouts, so ``Event.set`` from the handler could deadlock the shutdown)."""

from __future__ import annotations

import contextlib
import signal
import threading
import time
from collections.abc import Callable, Iterator
from types import FrameType

__all__ = ["POLL", "StopRequest", "handling"]

POLL = 0.1
"""Seconds between looks at whether a signal asked the program to stop."""


class StopRequest:
    """A signal handler that notes which signal asked to stop; ``signal`` is None until one did."""

    def __init__(self) -> None:
        self.signal: int | None = None

    def __call__(self, signum: int, frame: FrameType | None) -> None:
        self.signal = signum

    def wait(self, until: Callable[[float], bool] | None = None) -> None:
        """Return once a signal arrived, or once ``until(POLL)`` (a wait of at most POLL seconds that
        says whether to stop, such as ``Event.wait``) returns true."""
        while self.signal is None:
            if until is None:
                time.sleep(POLL)
            elif until(POLL):
                return


@contextlib.contextmanager
def handling(request: StopRequest, *signals: signal.Signals) -> Iterator[None]:
    """Let ``request`` take ``signals`` for the block, then restore the handlers it found. Only the main
    thread may install handlers: elsewhere the block runs with the process's handlers as they are."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {number: signal.signal(number, request) for number in signals}
    try:
        yield
    finally:
        for number, handler in previous.items():
            signal.signal(number, handler)
