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

With other threads running, C's own ``stdout`` and ``stderr`` streams are held instead: made fully
buffered for the duration, so that what C code prints (the banner goes to ``stderr``, which C leaves
unbuffered) waits in their buffers, and then those buffers are discarded (``__fpurge``) and the streams
buffered as before. Python writes to the descriptors, not through C's streams, so the server's own
lines are untouched; only C output of another thread during the import would be lost too. Where the C
library lacks those names (not glibc or musl), the banner is let through.
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
        with _held_c_streams():
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


_IOFBF, _IOLBF, _IONBF = 0, 1, 2  # setvbuf's modes (glibc, musl)
_HELD = threading.Lock()  # the C streams are the process's: one holder at a time
# The buffers C's streams are given, kept for the life of the process: setvbuf with no buffer keeps
# the one a stream has, and a buffer freed under it crashed the process when it exited.
_BUFFERS = (ctypes.create_string_buffer(1 << 16), ctypes.create_string_buffer(1 << 16))


@contextlib.contextmanager
def _held_c_streams() -> Iterator[None]:
    """What C code prints to ``stdout`` and ``stderr`` meanwhile is dropped, the descriptors untouched."""
    try:
        libc = ctypes.CDLL(None)
        streams = [ctypes.c_void_p.in_dll(libc, name) for name in ("stdout", "stderr")]
        purge = libc.__fpurge
    except (AttributeError, ValueError, OSError):  # another C library: let it through
        yield
        return
    # as C had them after: stdout by line on a terminal, else in blocks; stderr unbuffered
    modes = [_IOLBF if os.isatty(1) else _IOFBF, _IONBF]
    with _HELD:
        for stream, buffer in zip(streams, _BUFFERS, strict=True):
            libc.fflush(stream)
            libc.setvbuf(stream, buffer, _IOFBF, len(buffer))
        try:
            yield
        finally:
            for stream, buffer, mode in zip(streams, _BUFFERS, modes, strict=True):
                purge(stream)
                if mode == _IONBF:
                    libc.setvbuf(stream, None, mode, 0)
                else:
                    libc.setvbuf(stream, buffer, mode, len(buffer))


with quiet_output():  # the banner is printed when pybullet is first imported, too
    import pybullet  # noqa: F401
