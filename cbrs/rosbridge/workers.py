"""A small pool of daemon threads for service handlers, which may block for seconds.

Unlike ``concurrent.futures.ThreadPoolExecutor`` it can be joined with a deadline: a handler stuck in a
robot task must not hang the server's shutdown. Threads start on demand, up to ``size``.
"""

from __future__ import annotations

import logging
import queue
import threading
import time
from collections.abc import Callable

log = logging.getLogger("cbrs.rosbridge")

Job = Callable[[], None]


class WorkerPool:
    """Run jobs on up to ``size`` threads; ``shutdown`` then ``join`` to stop them."""

    def __init__(self, size: int, name: str = "cbrs-rosbridge-service") -> None:
        if size < 1:
            raise ValueError(f"a worker pool needs at least one thread, not {size}")
        self.size = size
        self._name = name
        self._jobs: queue.SimpleQueue[Job | None] = queue.SimpleQueue()
        self._threads: list[threading.Thread] = []
        self._lock = threading.Lock()
        self._waiting = 0  # jobs submitted and not yet taken
        self._idle = 0
        self._closed = False

    def submit(self, job: Job) -> None:
        with self._lock:
            if self._closed:
                raise RuntimeError("the worker pool is shut down")
            self._waiting += 1
            self._jobs.put(job)
            if self._waiting > self._idle and len(self._threads) < self.size:
                thread = threading.Thread(target=self._work, name=f"{self._name}-{len(self._threads) + 1}", daemon=True)
                self._threads.append(thread)
                thread.start()

    def shutdown(self) -> None:
        """Take no more jobs; jobs not started are skipped, threads end after their current job."""
        with self._lock:
            self._closed = True
            for _ in self._threads:
                self._jobs.put(None)

    def join(self, timeout: float) -> int:
        """Wait up to ``timeout`` seconds for the threads to end; returns how many are still running."""
        deadline = time.monotonic() + timeout
        for thread in list(self._threads):
            thread.join(max(0.0, deadline - time.monotonic()))
        alive = sum(thread.is_alive() for thread in self._threads)
        if alive:
            log.warning("%d service handler(s) still running after %.1f s, left as daemon threads", alive, timeout)
        return alive

    def _work(self) -> None:
        while True:
            with self._lock:
                self._idle += 1
            job = self._jobs.get()
            with self._lock:
                self._idle -= 1
                if job is not None:
                    self._waiting -= 1
                skip = self._closed
            if job is None or skip:
                if job is None:
                    return
                continue
            try:
                job()
            except Exception:  # jobs report their own errors; this is a last resort
                log.exception("service job failed")
