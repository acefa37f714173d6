"""A stop signal is noted, never raised, and the handlers found are put back."""

from __future__ import annotations

import os
import signal
import threading

from cbrs.stop_signals import StopRequest, handling


def test_a_signal_inside_the_block_is_noted_and_the_old_handler_restored() -> None:
    before = signal.getsignal(signal.SIGTERM)
    request = StopRequest()
    with handling(request, signal.SIGTERM):
        assert id(signal.getsignal(signal.SIGTERM)) == id(request)
        os.kill(os.getpid(), signal.SIGTERM)  # this process, by its PID; noted, so nothing is raised here
        request.wait()  # returns: the signal arrived
    assert request.signal == signal.SIGTERM
    assert signal.getsignal(signal.SIGTERM) is before


def test_the_wait_also_ends_when_its_condition_does() -> None:
    closed = threading.Event()
    looked: list[float] = []

    def until(timeout: float) -> bool:
        looked.append(timeout)
        if len(looked) == 3:
            closed.set()
        return closed.wait(timeout)

    StopRequest().wait(until=until)
    assert len(looked) == 3 and all(timeout > 0 for timeout in looked)


def test_outside_the_main_thread_the_handlers_are_left_alone() -> None:
    before = signal.getsignal(signal.SIGTERM)
    seen: list[object] = []

    def elsewhere() -> None:
        with handling(StopRequest(), signal.SIGTERM):
            seen.append(signal.getsignal(signal.SIGTERM))

    thread = threading.Thread(target=elsewhere)
    thread.start()
    thread.join(timeout=10)
    assert seen == [before]
