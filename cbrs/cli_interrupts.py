"""Ctrl-C while a command writes: once a write has begun it is one transaction that stands when it ends,
so an interrupt then is held until the command is done, and said so, instead of "Aborted!" printed over
a load that was written all the same (new-user CLI repro 08: Ctrl-C during a 30 s write waited for it,
printed "Aborted!", and the 600,000 triples were in the store, graph:entailed not brought up to date)."""

from __future__ import annotations

import signal
import threading
from types import FrameType, TracebackType
from typing import Any

import click


class HeldInterrupts:
    """A context in which :meth:`hold` makes the first Ctrl-C wait for the end of the block; a second one
    interrupts at once, as before (for a write that hangs on a server that went away)."""

    def __init__(self) -> None:
        self.held = False
        self.interrupted = False
        self._previous: Any = None

    def __enter__(self) -> HeldInterrupts:
        return self

    def hold(self, what: str) -> None:
        """From now on, until the block ends, the first Ctrl-C is held: ``what`` is being written."""
        if self.held or threading.current_thread() is not threading.main_thread():
            return
        self.held = True
        self._what = what
        self._previous = signal.signal(signal.SIGINT, self._interrupt)

    def _interrupt(self, signum: int, frame: FrameType | None) -> None:
        if self.interrupted:
            raise KeyboardInterrupt
        self.interrupted = True
        click.echo(
            f"\ncbrs: Ctrl-C while {self._what}: that is one transaction, which stands once it ends; "
            "waiting for it to end (Ctrl-C again stops waiting where the write can be left: a request to "
            "a remote store)",
            err=True,
        )

    def __exit__(
        self, kind: type[BaseException] | None, error: BaseException | None, trace: TracebackType | None
    ) -> None:
        if self.held:
            signal.signal(signal.SIGINT, self._previous)
            self.held = False
