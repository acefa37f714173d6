"""Keep pybullet's start-up banner off the terminal.

pybullet's C code prints "pybullet build time: ..." when it is imported and when a client connects,
which spoils machine-readable output such as ``cbrs run --json``. The banner is written to the file
descriptors directly, so they are redirected there, not at the Python level.
"""

from __future__ import annotations

import contextlib
import ctypes
import os
import sys
from collections.abc import Iterator

__all__ = ["quiet_output"]


@contextlib.contextmanager
def quiet_output() -> Iterator[None]:
    """Send what C code writes to file descriptors 1 and 2 to the null device for the duration."""
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
