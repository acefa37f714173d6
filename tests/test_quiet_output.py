"""pybullet's banner is kept off the terminal by redirecting descriptors 1 and 2, which are the whole
process's: with other threads running (a server) the redirection would swallow their output, and a
Ctrl-C while pybullet was imported on a thread left ``cbrs serve``'s "stopped" in the null device."""

from __future__ import annotations

import os
import subprocess
import sys
import threading

from cbrs.sim.quiet import quiet_output


def _stdout_identity() -> tuple[int, int]:
    status = os.fstat(1)
    return status.st_dev, status.st_ino


def test_with_another_thread_running_the_descriptors_are_left_alone() -> None:
    release = threading.Event()
    other = threading.Thread(target=release.wait, args=(10,), daemon=True)
    other.start()
    try:
        before = _stdout_identity()
        with quiet_output():
            assert _stdout_identity() == before
    finally:
        release.set()
        other.join(10)


def test_alone_in_its_process_it_keeps_c_output_off_stdout() -> None:
    """A CLI command is one thread: what C code writes during the block goes nowhere, and stdout is
    whole again after it."""
    program = (
        "import ctypes, os, threading\n"
        "from cbrs.sim.quiet import quiet_output\n"
        "assert threading.active_count() == 1\n"
        "with quiet_output():\n"
        "    os.write(1, b'hidden\\n')\n"
        "    ctypes.CDLL(None).printf(b'hidden too\\n')\n"
        "os.write(1, b'shown\\n')\n"
    )
    done = subprocess.run([sys.executable, "-c", program], capture_output=True, text=True, timeout=60, check=False)
    assert done.returncode == 0, done.stderr
    assert done.stdout.splitlines() == ["shown"]
