"""Keep pybullet's start-up banner off the terminal.

pybullet's C code prints "pybullet build time: ..." when it is imported (and a GUI client may print
when it connects), which spoils machine-readable output such as ``cbrs run --json``. The banner is
written to the file descriptors directly, so they are redirected there, not at the Python level.

A redirection of descriptors 1 and 2 is the whole process's, not the calling thread's: in ``cbrs
serve`` pybullet is first imported on a thread (a task run, the first page's preload), and while it
was, the server's own output went to the null device; a Ctrl-C then lost "stopped" for good, the
thread being stopped before it could put the descriptors back. So the banner is kept off only while
the calling thread is the process's only one (a CLI command); with other threads running it is let
through: one line in a server's log is harmless, its own lines lost are not.
"""

from __future__ import annotations

import contextlib
import ctypes
import os
import sys
import threading
from collections.abc import Iterator

__all__ = ["quiet_output"]


@contextlib.contextmanager
def quiet_output() -> Iterator[None]:
    """Send what C code writes to file descriptors 1 and 2 to the null device for the duration, when
    no other thread runs (their output would go there too)."""
    if threading.active_count() > 1:
        yield
        return
    sys.stdout.flush()
    sys.stderr.flush()
    try:
        saved = [os.dup(1), os.dup(2)]
    except OSError:  # no standard descriptors (embedded interpreters): nothing to silence
        yield
        return
    try:
        with open(os.devnull, "w") as sink:
            os.dup2(sink.fileno(), 1)
            os.dup2(sink.fileno(), 2)
            try:
                yield
            finally:
                ctypes.CDLL(None).fflush(None)  # C's buffers go to the sink now, not to the terminal later
    finally:
        for fd, copy in zip((1, 2), saved, strict=True):
            os.dup2(copy, fd)
            os.close(copy)


with quiet_output():  # the banner is printed when pybullet is first imported, too
    import pybullet  # noqa: F401
