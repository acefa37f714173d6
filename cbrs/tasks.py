"""Tasks started by clients of ``cbrs serve``: one run at a time in the simulated home, followed by events.

A run composes the task, executes it in a fresh headless world and records its events; listeners (the
rosbridge topics, the browser) receive every event as it happens, from the run's thread.
"""

from __future__ import annotations

import itertools
import logging
import threading
import time
from collections import OrderedDict
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Any

from actions.composer import Composer
from actions.events import Event
from actions.model import ActionLibrary, resolve_task
from actions.runner import run_task
from kb import KnowledgeBase
from kb.errors import KnowledgeBaseError
from kb.namespaces import expand, shorten

log = logging.getLogger("cbrs.tasks")

Listener = Callable[[str, dict[str, Any]], None]

# Topic on which the runner announces runs starting and ending (the executor's own topics carry the steps).
RUN_TOPIC = "/cbrs/events"


class TaskBusyError(KnowledgeBaseError):
    http_status = 409

    def __init__(self, running: str) -> None:
        self.running = running
        super().__init__(f"task run {running} is still going; one task runs at a time")


class UnknownComponentError(KnowledgeBaseError):
    http_status = 400

    def __init__(self, names: list[str]) -> None:
        self.names = names
        super().__init__(f"no simulated component {', '.join(names)}")


class UnknownRunError(KnowledgeBaseError):
    http_status = 404

    def __init__(self, run_id: str) -> None:
        self.run_id = run_id
        super().__init__(f"no task run {run_id!r}")


@dataclass
class TaskRun:
    id: str
    task: str
    seed: int
    faults: tuple[str, ...]
    status: str = "running"  # then succeeded, failed, no-plan or error
    started: float = field(default_factory=time.time)
    finished: float | None = None
    events: list[dict[str, Any]] = field(default_factory=list)
    result: dict[str, Any] | None = None
    error: str | None = None
    done: threading.Event = field(default_factory=threading.Event, repr=False)

    def to_dict(self, with_events: bool = True) -> dict[str, Any]:
        found: dict[str, Any] = {
            "id": self.id,
            "task": self.task,
            "seed": self.seed,
            "faults": list(self.faults),
            "status": self.status,
            "started": self.started,
            "finished": self.finished,
        }
        if self.error:
            found["error"] = self.error
        if with_events:
            found["events"] = list(self.events)
        if self.result is not None:
            found["result"] = self.result
        return found


class TaskRunner:
    """Starts task runs in the simulated home, one at a time, and keeps the last ``keep`` of them."""

    def __init__(self, kb: KnowledgeBase, lock: threading.RLock, keep: int = 20) -> None:
        self.kb = kb
        self.lock = lock
        self.keep = keep
        self._runs: OrderedDict[str, TaskRun] = OrderedDict()
        self._listeners: list[Listener] = []
        self._guard = threading.Lock()
        self._active: tuple[TaskRun, threading.Thread] | None = None
        self._ids = itertools.count(1)

    def subscribe(self, listener: Listener) -> Callable[[], None]:
        """Call ``listener(topic, message)`` for every event of every run; returns the unsubscribe call."""
        with self._guard:
            self._listeners.append(listener)
        return lambda: self._unsubscribe(listener)

    def start(self, task: str, seed: int = 0, faults: Iterable[str] = ()) -> TaskRun:
        """Check ``task`` and ``faults``, then run the task in the background; returns at once."""
        failing = tuple(expand(f) for f in faults)
        _check_components(failing)
        self._refuse_if_busy()  # before taking the lock, which a run holds until it ends
        with self.lock:
            resolve_task(self.kb, ActionLibrary.from_kb(self.kb), task)  # an unknown task fails here, not in the thread
        with self._guard:
            self._refuse_if_busy()
            run = TaskRun(f"run-{next(self._ids)}", task, seed, failing)
            thread = threading.Thread(target=self._run, args=(run,), name=f"cbrs-{run.id}", daemon=True)
            self._active = (run, thread)
            self._runs[run.id] = run
            while len(self._runs) > self.keep:
                self._runs.popitem(last=False)
        self._emit(RUN_TOPIC, {"event": "run_started", "run": run.id, "task": task})
        thread.start()
        return run

    def _refuse_if_busy(self) -> None:
        active = self._active
        if active is not None and active[1].is_alive():
            raise TaskBusyError(active[0].id)

    def run(self, task: str, seed: int = 0, faults: Iterable[str] = (), timeout: float = 300.0) -> TaskRun:
        """Start ``task`` and wait (at most ``timeout`` seconds) until it ends."""
        run = self.start(task, seed, faults)
        run.done.wait(timeout)
        return run

    def get(self, run_id: str) -> TaskRun:
        with self._guard:
            if run_id not in self._runs:
                raise UnknownRunError(run_id)
            return self._runs[run_id]

    def runs(self) -> list[TaskRun]:
        with self._guard:
            return list(self._runs.values())

    def close(self, timeout: float = 30.0) -> None:
        """Wait (bounded) for a run still going; it cannot be interrupted mid-step."""
        active = self._active
        if active is not None:
            active[1].join(timeout)

    def _run(self, run: TaskRun) -> None:
        from sim.components import SimEnvironment  # pybullet loads only when a task runs
        from sim.world import open_world

        def follow(event: Event) -> None:
            message = dict(event.message, run=run.id)
            run.events.append({"topic": event.topic, **message})
            self._emit(event.topic, message)

        try:
            with self.lock, open_world(seed=run.seed) as world:
                environment = SimEnvironment(world, self.kb)
                result = run_task(self.kb, run.task, environment, run.faults, Composer(self.kb), follow)
                found = result.to_dict()
                found["sim_seconds"] = round(world.time, 3)
            run.result = found
            if result.report is None:
                run.status = "no-plan"
            else:
                run.status = "succeeded" if result.succeeded else "failed"
        except Exception as error:  # a run must end with a status, whatever broke
            log.exception("task run %s failed", run.id)
            run.status, run.error = "error", f"{type(error).__name__}: {error}"
        finally:
            run.finished = time.time()
            run.done.set()
            self._emit(RUN_TOPIC, {"event": "run_finished", "run": run.id, "task": run.task, "status": run.status})

    def _emit(self, topic: str, message: dict[str, Any]) -> None:
        with self._guard:
            listeners = list(self._listeners)
        for listener in listeners:
            try:
                listener(topic, message)
            except Exception:  # one broken listener must not stop the run or the others
                log.exception("task event listener failed on %s", topic)

    def _unsubscribe(self, listener: Listener) -> None:
        with self._guard:
            if listener in self._listeners:
                self._listeners.remove(listener)


def _check_components(failing: tuple[str, ...]) -> None:
    if not failing:
        return
    from sim.components import implementations

    known = implementations()
    unknown = [shorten(f) for f in failing if f not in known]
    if unknown:
        raise UnknownComponentError(unknown)
