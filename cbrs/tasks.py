"""Tasks started by clients of ``cbrs serve``: one run at a time in the simulated home, followed by events.

A run composes the task, executes it in a fresh headless world and records its events; listeners (the
rosbridge topics, the browser) receive every event as it happens, from the run's thread. A task no plan
can come of ends ``no-plan`` before the world is built (:func:`refusal_in_home`, as ``cbrs run`` refuses it).

While a run goes, a run started waits in the runner's queue when it has room (``run_queue``, the
``CBRS_RUN_QUEUE`` setting; 0 by default: refused, :class:`TaskBusyError`, as before the queue): it is
``queued`` with its ``position`` (1: next), starts when the run before it ends, and is planned then, on the
world as that run left it. A cancel takes it out of the queue; a server stopping ends those waiting
``cancelled``, each with its ``reason``.

The runner also keeps the ceiling camera's latest view (a JPEG and a counter). A run renders it only
while someone watches (:meth:`TaskRunner.watch`: the browser's MJPEG stream, a still asked for): when the
run starts, after every step that ends, and within ``FRAME_CHECK_STEPS`` physics steps of a watcher
joining mid-run; and once as the run leaves the home, for whoever looks later. A headless served run
renders nothing else for the picture. Before any run the idle home is rendered once, when first asked.
Frame listeners (:meth:`TaskRunner.on_frame`) hear of each new frame; :meth:`TaskRunner.wait_frame`
blocks (bounded) until one comes.
"""

from __future__ import annotations

import difflib
import io
import itertools
import logging
import threading
import time
from collections import OrderedDict
from collections.abc import Callable, Iterable, Sequence
from contextlib import AbstractContextManager, nullcontext
from dataclasses import dataclass, field
from enum import Enum
from typing import TYPE_CHECKING, Any

from cbrs.extras import installed, require
from cbrs.iri_tail import tail
from cbrs.kb import KnowledgeBase
from cbrs.kb.derived_prefixes import StoreNames
from cbrs.kb.errors import KnowledgeBaseError
from cbrs.kb.namespaces import expand, shorten, store_names
from cbrs.settings import setting

if TYPE_CHECKING:
    from cbrs.actions.composer import Composer
    from cbrs.actions.events import Event
    from cbrs.actions.remote import Transport
    from cbrs.actions.runner import RunResult
    from cbrs.kb import Advertisement
    from cbrs.kb.semantic_map import SemanticMap
    from cbrs.sim_sensors import SimSensors

log = logging.getLogger("cbrs.tasks")

Listener = Callable[[str, dict[str, Any]], None]

# Topic on which the runner announces runs starting and ending (the executor's own topics carry the steps).
RUN_TOPIC = "/cbrs/events"
#: The executor's topics whose messages name the run's task (``task``: the plan's task, an IRI); the runner
#: adds the run's ``iri`` and ``shown`` to them, as to its own (docs/rosbridge.md, "How a run names its task").
TASK_TOPICS = ("/cbrs/task", "/cbrs/task_progress")


CAMERA = "CeilingCamera01"  # the view the browser shows (in the bundled home it covers both scenarios' rooms; _view)
JPEG_QUALITY = 80
#: How often (in physics steps, 1/240 s each) a run looks whether a watcher who joined wants a frame now.
FRAME_CHECK_STEPS = 12


@dataclass(frozen=True)
class CameraFrame:
    """One view of the home: ``number`` counts up from 1 across runs; ``run`` is None for the idle home."""

    number: int
    jpeg: bytes
    run: str | None
    taken: float = field(default_factory=time.time)


class TaskBusyError(KnowledgeBaseError):
    """A run started while another goes, with no queue to wait in (``run_queue`` 0)."""

    http_status = 409

    def __init__(self, running: str, message: str | None = None) -> None:
        self.running = running
        super().__init__(message or f"task run {running} is still going; one task runs at a time")


class RunQueueFullError(TaskBusyError):
    """A run started while another goes and ``limit`` runs already wait: the queue is full."""

    def __init__(self, running: str, waiting: int, limit: int) -> None:
        self.waiting, self.limit = waiting, limit
        runs = "run waits" if waiting == 1 else "runs wait"
        super().__init__(
            running,
            f"task run {running} is still going and the run queue is full: {waiting} {runs}, as many as it "
            f"holds (run_queue {limit}); start again when one has ended",
        )


class TasksDisabledError(KnowledgeBaseError):
    """A read-only server runs no tasks: a run writes its plan and the world graph into the store."""

    http_status = 403
    kind = "forbidden"

    def __init__(self) -> None:
        super().__init__("task runs are disabled: this server is read-only (a run writes its plan and the world graph)")


class UnknownComponentError(KnowledgeBaseError):
    http_status = 400

    def __init__(self, names: list[str], near: dict[str, list[str]] | None = None) -> None:
        """``names``: those given that no component is (simulated or over the bridge: a server's run reaches
        both); ``near``: for some of them, the nearest names of components that are, as ``cbrs run`` says."""
        self.names = names
        self.near = dict(near or {})
        said = [n + (f" (did you mean {' or '.join(self.near[n])}?)" if self.near.get(n) else "") for n in names]
        super().__init__(f"no component {', '.join(said)}")


class RunOptionError(KnowledgeBaseError):
    """A composition option of a run (``objective``, ``base_ties``, ``near_misses``) given a value the run does
    not take: it names the field, the value and what is allowed, as ``cbrs run`` refuses its options."""

    http_status = 400

    def __init__(self, field: str, value: object, allowed: str) -> None:
        self.field, self.value = field, value
        super().__init__(f"{field} {value!r} is not {allowed}")


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
    fault_rate: float = 0.0  # random faults, seeded with ``seed`` (actions.faults.RandomFaults)
    repeat_failures: int = 1  # actions.replanning.ReplanPolicy.max_repeats
    iri: str = ""  # the requirement or action ``task`` names
    status: str = "running"  # or queued before it; then succeeded, failed, cancelled, no-plan or error
    started: float = field(default_factory=time.time)
    finished: float | None = None
    events: list[dict[str, Any]] = field(default_factory=list)
    result: dict[str, Any] | None = None
    error: str | None = None
    done: threading.Event = field(default_factory=threading.Event, repr=False)
    cancel_requested: threading.Event = field(default_factory=threading.Event, repr=False)
    # the composition options cbrs run takes (--objective, --base-ties, --near-misses), with its defaults
    objective: str = "similarity"  # actions.composer.Objective
    base_ties: str = "nearest"  # actions.base_choice.BaseTies
    near_misses: int = 3  # ComposeConfig.near_misses (TaskRunner.start fills in its default)
    shown: str = ""  # the task as the pages name it (:func:`shown_name`; TaskRunner.start fills it in)
    position: int | None = None  # while queued: its place in the queue, 1 the next to start
    queued: float | None = None  # when it was queued (None: it started at once)
    reason: str | None = None  # why it ended without starting (taken out of the queue)

    def to_dict(self, with_events: bool = True) -> dict[str, Any]:
        found: dict[str, Any] = {
            "id": self.id,
            "task": self.task,
            "seed": self.seed,
            "faults": list(self.faults),
            "fault_rate": self.fault_rate,
            "repeat_failures": self.repeat_failures,
            "objective": self.objective,
            "base_ties": self.base_ties,
            "near_misses": self.near_misses,
            "iri": self.iri,
            "shown": self.shown or self.task,
            "status": self.status,
            "started": self.started,
            "finished": self.finished,
        }
        if self.error:
            found["error"] = self.error
        if self.status == "queued" and self.position is not None:
            found["position"] = self.position
        if self.reason:
            found["reason"] = self.reason
        if with_events:
            found["events"] = list(self.events)
        if self.result is not None:
            found["result"] = self.result
        return found


def shown_name(listed: str, iri: str, shortened: Callable[[str], str] | None = None) -> str:
    """A task as the pages, a run's events and its record name it (the one rule all of them use): one asked
    for by a prefixed name as written (``act:FetchMyPen``, ``lab10:SwitchOnTheReadingLamp``); one of cbrs's
    own namespaces by its bare name as written (``FetchMyPen``, what ``cbrs run`` takes), by its IRI with its
    prefix (``req:FetchMyPen``); a lab's, asked for by its bare name or its IRI, by the prefix derived for
    its namespace (``lab10:SwitchOnTheReadingLamp``), since the bare name says not whose it is; and by an IRI
    that no prefix covers, its tail (``lab.ttl#Fetch(Pen)``, :func:`cbrs.iri_tail.tail`), as every page shows
    such an IRI: the whole IRI is the run's ``iri``, for programs.

    ``shortened``: how the caller shortens an IRI with cbrs's prefixes and the store's derived ones (the pages
    pass their own, ``cbrs.web.links.short``); by default :func:`shorten`, within :func:`store_names`."""
    typed = listed[1:-1] if listed.startswith("<") and listed.endswith(">") else listed
    if not iri or (":" in typed and typed != iri):  # a prefixed name: as written
        return listed
    with store_names(None):
        declared = shorten(iri)
    if declared != iri:  # cbrs's own namespaces: as the list names it
        return listed if ":" not in typed else declared
    derived = (shortened or shorten)(iri)
    if derived != iri:
        return derived
    return listed if ":" not in typed else tail(iri)


def in_line(position: int) -> str:
    """Where a queued run stands, as the pages and the bridge say it: "next in line", "3rd in line"."""
    if position == 1:
        return "next in line"
    suffix = "th" if 10 <= position % 100 <= 20 else {1: "st", 2: "nd", 3: "rd"}.get(position % 10, "th")
    return f"{position}{suffix} in line"


def _naming(run: TaskRun) -> dict[str, str]:
    """How every message of a run names it and its task: ``task`` as asked for (kept as it was), ``iri``
    and ``shown`` as the run's record has them."""
    return {"run": run.id, "task": run.task, "iri": run.iri, "shown": run.shown or run.task}


def _view(world: Any, wanted: str) -> str:
    """The camera whose frames the browser shows: ``wanted`` when the home has it, else the first by name
    of the home's cameras that look straight down (a lab's own home names its own ceiling cameras), else
    ``wanted`` (the world then says it has no such camera)."""
    if wanted in world.cameras:
        return wanted
    down = sorted(camera.name for camera in world.map.cameras.values() if camera.looks_down)
    return down[0] if down else wanted


class TaskRunner:
    """Starts task runs in the simulated home, one at a time, queues up to ``queue`` more while one goes
    (None: the ``run_queue`` setting), and keeps the last ``keep`` runs that ended, beside those to come."""

    def __init__(
        self,
        kb: KnowledgeBase,
        lock: threading.RLock,
        keep: int = 20,
        camera: str | None = CAMERA,
        read_only: bool = False,
        queue: int | None = None,
    ) -> None:
        size = int(setting("run_queue").resolve()) if queue is None else queue
        if isinstance(size, bool) or size < 0:
            raise ValueError(f"a run queue holds 0 runs or more, not {queue!r}")
        self.queue_size = size
        """How many runs may wait while one goes (0: a run started then is refused)."""
        self._waiting: list[TaskRun] = []
        self._closed = False
        self.kb = kb
        self.lock = lock
        self.read_only = read_only
        self.keep = keep
        self.camera = camera  # None: take no frames (runs are a little faster)
        self._frame: CameraFrame | None = None
        self._frame_ready = threading.Condition()
        self._frame_listeners: list[Callable[[CameraFrame], None]] = []
        self._idle_render = threading.Lock()
        self._watchers = 0  # open camera streams and stills being taken (watch)
        self._frame_wanted = threading.Event()  # a watcher joined mid-run: the run renders at its next check
        self._runs: OrderedDict[str, TaskRun] = OrderedDict()
        self._listeners: list[Listener] = []
        self._guard = threading.Lock()
        self._active: tuple[TaskRun, threading.Thread] | None = None
        self._ids = itertools.count(1)
        self.transport: Callable[[], Transport | None] | None = None
        """How a run reaches components in other processes (the server's own bridge connection)."""
        self.sensors: SimSensors | None = None
        """The simulation's sensors on the bridge (``/sim/capture``, ``/sim/load``): they answer from each
        run's world while it runs."""

    def subscribe(self, listener: Listener) -> Callable[[], None]:
        """Call ``listener(topic, message)`` for every event of every run; returns the unsubscribe call."""
        with self._guard:
            self._listeners.append(listener)
        return lambda: self._unsubscribe(listener)

    def on_frame(self, listener: Callable[[CameraFrame], None]) -> Callable[[], None]:
        """Call ``listener(frame)`` for every new camera frame; returns the unsubscribe call."""
        with self._guard:
            self._frame_listeners.append(listener)

        def unsubscribe() -> None:
            with self._guard:
                if listener in self._frame_listeners:
                    self._frame_listeners.remove(listener)

        return unsubscribe

    def watch(self) -> Callable[[], None]:
        """Count a watcher of the camera until the returned call (idempotent): a run renders frames only
        while one watches. One joining mid-run asks the run for a frame now, which it renders within
        ``FRAME_CHECK_STEPS`` physics steps (:meth:`wait_frame` hears of it)."""
        with self._guard:
            self._watchers += 1
        if self.active() is not None:
            self._frame_wanted.set()
        released = threading.Event()

        def release() -> None:
            if not released.is_set():
                released.set()
                with self._guard:
                    self._watchers -= 1

        return release

    @property
    def watched(self) -> bool:
        """Whether someone watches the camera now (:meth:`watch`)."""
        return self._watchers > 0

    def current_frame(self, timeout: float) -> CameraFrame | None:
        """The camera's view now: while a run goes, a frame it renders for this call (waiting at most
        ``timeout`` seconds, else the latest); otherwise the latest frame, as :meth:`frame`."""
        release = self.watch()
        try:
            latest = self.frame()
            if self.active() is None:
                return latest
            return self.wait_frame(latest.number if latest is not None else 0, timeout) or self._frame
        finally:
            release()

    def frame(self) -> CameraFrame | None:
        """The latest camera frame; before any run, the idle home is rendered once (about half a second).

        None when the runner takes no frames.
        """
        if self._frame is None and self.camera is not None:
            self._render_idle()
        return self._frame

    @property
    def frame_number(self) -> int:
        """The latest frame's number (0 before the first); renders nothing."""
        frame = self._frame
        return frame.number if frame is not None else 0

    def wait_frame(self, after: int, timeout: float) -> CameraFrame | None:
        """The first frame numbered above ``after``, waiting at most ``timeout`` seconds; None if none came."""
        with self._frame_ready:
            self._frame_ready.wait_for(lambda: self._frame is not None and self._frame.number > after, timeout)
            frame = self._frame
        return frame if frame is not None and frame.number > after else None

    def active(self) -> TaskRun | None:
        """The run going now, if any: one whose thread lives and whose result is not final yet (a run that
        ended, and said so on the run topic, frees the runner although its thread has a moment still to go:
        a listener starting the next run as it hears the end is not refused)."""
        active = self._active
        going = active is not None and active[0].finished is None and active[1].is_alive()
        return active[0] if active is not None and going else None

    def components(self) -> list[str]:
        """The IRIs of the simulated components, which a run may be told to fail (none without [sim])."""
        if not installed("sim"):
            return []
        from cbrs.sim.components import simulated

        return simulated(self.kb)

    def tasks(self) -> list[str]:
        """Every task the store can express, as a person types it (``cbrs.task_names.known_tasks``)."""
        from cbrs.task_names import known_tasks  # the planner loads with the first use, not at start-up

        with self.lock:
            return known_tasks(self.kb)

    def start(
        self,
        task: str,
        seed: int = 0,
        faults: Iterable[str] = (),
        fault_rate: float = 0.0,
        repeat_failures: int = 1,
        objective: str = "similarity",
        base_ties: str = "nearest",
        near_misses: int | None = None,
    ) -> TaskRun:
        """Check ``task`` and ``faults``, then run the task in the background; returns at once.

        ``task`` is any requirement or action of the store, named as ``cbrs run`` takes it (a bare local
        name, a prefixed name or an IRI); an unknown one fails with a did-you-mean (``TaskNameError``).
        ``fault_rate`` breaks each component with that probability at a random moment, seeded by ``seed``.
        ``repeat_failures`` bounds how often a re-plan may meet the same failure with nothing changed
        (``ReplanPolicy.max_repeats``). ``objective``, ``base_ties`` and ``near_misses`` compose as ``cbrs run
        --objective --base-ties --near-misses`` do (None: ``ComposeConfig.near_misses``); a value it does not
        take fails with :class:`RunOptionError`.
        """
        if self.read_only:
            raise TasksDisabledError()
        require("sim", "a task run")
        from cbrs.actions.faults import RandomFaults  # the planner loads with the first run, not at start-up
        from cbrs.actions.model import ActionLibrary, resolve_task
        from cbrs.actions.replanning import ReplanPolicy
        from cbrs.task_names import task_iri

        RandomFaults(seed, fault_rate)  # an impossible rate fails here (FaultSpecError), not in the thread
        ReplanPolicy(max_repeats=repeat_failures)  # so does a negative bound (ReplanPolicyError)
        near_misses = _check_options(objective, base_ties, near_misses)
        with store_names(StoreNames(lambda: self.kb)):  # the names a run's texts and cbrs run --fail take
            failing = tuple(expand(f) for f in faults)
            _check_components(self.kb, failing)
        self._refuse_if_full()  # a run with no room to wait is refused before its task is checked
        with self.lock:
            library = ActionLibrary.from_kb(self.kb)
            iri = task_iri(self.kb, task, library)  # an unknown task fails here, not in the thread
            resolve_task(self.kb, library, iri)
            with store_names(StoreNames(lambda: self.kb)):
                shown = shown_name(task, iri)
        with self._guard:
            ahead = self._refuse_if_full()
            run = TaskRun(f"run-{next(self._ids)}", task, seed, failing, fault_rate, repeat_failures, iri)
            run.objective, run.base_ties, run.near_misses, run.shown = objective, base_ties, near_misses, shown
            self._runs[run.id] = run
            self._forget_old()
            if ahead is not None:  # room in the queue: it starts when the runs before it have ended
                run.status, run.queued = "queued", run.started
                self._waiting.append(run)
                run.position = len(self._waiting)
            else:
                thread = threading.Thread(target=self._go, args=(run,), name=f"cbrs-{run.id}", daemon=True)
                self._active = (run, thread)
        if ahead is not None:
            log.info("task run %s (%s) queued, %s behind %s", run.id, run.task, in_line(run.position or 1), ahead.id)
            self._emit(RUN_TOPIC, {"event": "run_queued", **_naming(run), "status": "queued"})
            return run
        self._emit(RUN_TOPIC, {"event": "run_started", **_naming(run)})
        thread.start()
        return run

    def _refuse_if_full(self) -> TaskRun | None:
        """The run a run started now would wait behind (the last queued, else the one going); None when
        none goes; :class:`TaskBusyError` (:class:`RunQueueFullError`) when the queue has no room."""
        going = self.active()
        waiting = list(self._waiting)
        if going is None and not waiting:
            return None
        running = going.id if going is not None else waiting[0].id
        if self.queue_size == 0:
            raise TaskBusyError(running)
        if len(waiting) >= self.queue_size:
            raise RunQueueFullError(running, len(waiting), self.queue_size)
        return waiting[-1] if waiting else going

    def waiting(self) -> list[TaskRun]:
        """The runs queued, the next to start first."""
        with self._guard:
            return list(self._waiting)

    def _forget_old(self) -> None:
        """Keep ``keep`` runs at most, forgetting the oldest that have ended (never one going or queued)."""
        while len(self._runs) > self.keep:
            ended = next((key for key, old in self._runs.items() if old.finished is not None), None)
            if ended is None:
                return
            del self._runs[ended]

    def _renumber(self) -> None:
        for place, queued in enumerate(self._waiting, 1):
            queued.position = place

    def _go(self, run: TaskRun) -> None:
        """A run's thread: the run, then the next queued run's turn (whatever ``_run`` is: a test's script)."""
        try:
            self._run(run)
        finally:
            self._promote(run)

    def _promote(self, before: TaskRun) -> None:
        """The next queued run made the one going, its thread started: it begins once ``before`` has
        said its end (:meth:`_run_queued`). A run started meanwhile (one that heard the end) queues behind it."""
        with self._guard:
            if self._closed or not self._waiting:
                return
            run = self._waiting.pop(0)
            run.position = None
            self._renumber()
            thread = threading.Thread(target=self._run_queued, args=(run, before), name=f"cbrs-{run.id}", daemon=True)
            self._active = (run, thread)
            thread.start()

    def _run_queued(self, run: TaskRun, before: TaskRun) -> None:
        """A queued run's thread: wait until the run before it has ended (its ``run_finished`` said), then
        run it, planned now on the world as that run left it; stopped or shut down meanwhile, it ends
        ``cancelled`` without starting."""
        before.done.wait()
        if run.cancel_requested.is_set() or self._closed:
            why = "the server stopped" if self._closed else "it was stopped"
            self._end_unstarted(run, f"{why} before it started (it was queued)", promote=not self._closed)
            return
        run.status, run.started = "running", time.time()
        self._emit(RUN_TOPIC, {"event": "run_started", **_naming(run)})
        self._go(run)

    def _end_unstarted(self, run: TaskRun, reason: str, promote: bool) -> None:
        """End a queued run that never started: ``cancelled``, with ``reason``; said on the run topic."""
        run.status, run.reason, run.position, run.finished = "cancelled", reason, None, time.time()
        log.info("task run %s (%s) ended without starting: %s", run.id, run.task, reason)
        if promote:
            self._promote(run)
        self._emit(RUN_TOPIC, {"event": "run_finished", **_naming(run), "status": run.status})
        run.done.set()

    def run(
        self,
        task: str,
        seed: int = 0,
        faults: Iterable[str] = (),
        timeout: float = 300.0,
        fault_rate: float = 0.0,
        repeat_failures: int = 1,
        **options: Any,
    ) -> TaskRun:
        """Start ``task`` and wait (at most ``timeout`` seconds) until it ends; ``options``: the composition
        options :meth:`start` takes."""
        run = self.start(task, seed, faults, fault_rate, repeat_failures, **options)
        run.done.wait(timeout)
        return run

    def cancel(self, run_id: str) -> TaskRun:
        """Ask a run to stop after the step under way, or at once while it waits on a remote component's call,
        which it abandons (docs/execution.md; a run that has ended is left as it is). A queued run is taken
        out of the queue at once and ends ``cancelled`` without starting; those behind it move up."""
        run = self.get(run_id)
        run.cancel_requested.set()
        with self._guard:
            queued = run in self._waiting
            if queued:
                self._waiting.remove(run)
                self._renumber()
        if queued:
            self._end_unstarted(run, "taken out of the queue before it started (stopped)", promote=False)
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
        """End the queued runs (``cancelled``, the server stopping before they started), then wait (bounded)
        for a run still going; it cannot be interrupted mid-step. The log says which run was waited for and
        how it ended, or that it did not, for the administrator who stopped the server: the bridge and HTTP
        listeners are closed by then, so no client hears the run's verdict."""
        with self._guard:
            self._closed = True
            waiting, self._waiting = self._waiting, []
        for run in waiting:
            run.cancel_requested.set()
            self._end_unstarted(run, "the server stopped before it started (it was queued)", promote=False)
        if waiting:
            log.warning(
                "%d queued task run(s) ended without starting: %s", len(waiting), ", ".join(r.id for r in waiting)
            )
        active = self._active
        if active is None or not active[1].is_alive():
            return
        run, thread = active
        log.warning("task run %s (%s) is still going: waiting up to %g s for it to end", run.id, run.task, timeout)
        thread.join(timeout)
        if thread.is_alive():
            log.warning(
                "task run %s (%s) did not end within %g s: it stops with the server, mid-step; the plan and the "
                "world graph hold what it wrote before (each write one transaction)",
                run.id,
                run.task,
                timeout,
            )
        else:
            log.warning("task run %s (%s) ended: %s", run.id, run.task, run.status)

    def _run(self, run: TaskRun) -> None:
        # the run's texts (its answers, goals, reasons) name the store's own namespaces by the prefixes
        # derived for them, as `cbrs run` prints them and the pages show them (docs/web.md)
        with store_names(StoreNames(lambda: self.kb)):
            self._run_named(run)

    def _run_named(self, run: TaskRun) -> None:
        from cbrs.actions.composer import ComposeConfig, Composer, Objective
        from cbrs.kb.semantic_map import SemanticMap

        try:
            # The lock covers reading the taxonomy, actions and components as one view (an update cannot
            # land half-way); the run itself only writes its plan and the world graph, one transaction
            # each, so matchmaking, plans and queries go on while the robot moves.
            with self.lock:
                config = ComposeConfig(objective=Objective(run.objective), near_misses=run.near_misses)
                composer = Composer(self.kb, config)
                _ = composer.pool  # built now, under the lock
                semantic_map = SemanticMap.read(self.kb)
            transport = self.transport() if self.transport else None
            result = refusal_in_home(self.kb, run.iri, composer, transport)
            if result is not None:  # no plan can come of it: said without building the world (nothing simulated)
                found = {**result.to_dict(), "sim_seconds": 0.0}
            else:
                result, found = self._simulate(run, composer, semantic_map, transport)
            run.result = found
            run.status = _status(result)
        except Exception as error:  # a run must end with a status, whatever broke
            if isinstance(error, KnowledgeBaseError):  # refused on purpose (out of reach, ambiguous): one line
                log.warning("task run %s refused: %s", run.id, error)
            else:
                log.exception("task run %s failed", run.id)
            run.status, run.error = "error", f"{type(error).__name__}: {error}"
        finally:
            run.finished = time.time()
            # Said before done is set: whoever waited for the end (the bridge's action, a test) has heard it.
            self._emit(RUN_TOPIC, {"event": "run_finished", **_naming(run), "status": run.status})
            run.done.set()

    def _simulate(
        self, run: TaskRun, composer: Composer, semantic_map: SemanticMap, transport: Transport | None
    ) -> tuple[RunResult, dict[str, Any]]:
        """Run ``run`` in a fresh world built from ``semantic_map``: its result, and that as JSON with the
        simulated seconds."""
        from cbrs.actions.base_choice import BaseTies
        from cbrs.actions.colour_warnings import run_colour_risks
        from cbrs.actions.faults import RandomFaults
        from cbrs.actions.replanning import ReplanPolicy
        from cbrs.sim.components import SimEnvironment  # pybullet loads only when a task runs
        from cbrs.sim.world import open_world

        def follow(event: Event) -> None:
            message = dict(event.message, run=run.id)
            if event.topic in TASK_TOPICS:
                message.update(iri=run.iri, shown=run.shown or run.task)
            run.events.append({"topic": event.topic, **message})
            self._emit(event.topic, message)
            if event.topic == "/cbrs/task_progress" and message.get("event") in ("step_succeeded", "step_failed"):
                self._capture_watched(world, run.id)

        def wanted() -> None:  # a watcher joined mid-run: a frame now, not after the step under way
            if self._frame_wanted.is_set():
                self._capture_watched(world, run.id)

        self._frame_wanted.clear()
        with open_world(seed=run.seed, semantic_map=semantic_map) as world, self._sensing(world):
            self._capture_watched(world, run.id)
            stop_checking = world.on_steps(FRAME_CHECK_STEPS, wanted) if self.camera is not None else None
            environment = SimEnvironment(world, self.kb, transport)
            policy = RandomFaults(run.seed, run.fault_rate) if run.fault_rate > 0 else None
            result = run_task(
                self.kb,
                run.iri,
                environment,
                run.faults,
                composer,
                follow,
                fault_policy=policy,
                cancelled=run.cancel_requested.is_set,
                replan_policy=ReplanPolicy(max_repeats=run.repeat_failures),
                base_ties=BaseTies(run.base_ties),
            )
            if stop_checking is not None:
                stop_checking()
            self._capture(world, run.id)  # the home as the run leaves it, for whoever looks later
            found = result.to_dict()
            found["sim_seconds"] = round(world.time, 3)
            # what it perceived and looked for, painted where the cameras may not tell it (docs/simulation.md)
            warnings = run_colour_risks(self.kb, result, environment.looked_for())
            found["warnings"] = [risk.to_dict() for risk in warnings]
        return result, found

    def _sensing(self, world: Any) -> AbstractContextManager[Any]:
        """The simulation's sensors answering from ``world`` for the run (none offered: nothing to do)."""
        return self.sensors.watching(world) if self.sensors is not None else nullcontext()

    def _capture_watched(self, world: Any, run_id: str) -> None:
        """:meth:`_capture` while someone watches (a headless run renders nothing for the picture)."""
        self._frame_wanted.clear()
        if self.watched:
            self._capture(world, run_id)

    def _capture(self, world: Any, run_id: str | None) -> None:
        """Take the camera's view of ``world`` as the latest frame (a camera failure only costs the frame)."""
        if self.camera is None:
            return
        try:
            jpeg = _jpeg(world.camera(_view(world, self.camera)).capture().rgb)
        except Exception:
            log.exception("camera frame of %s failed", run_id or "the idle home")
            return
        self._publish_frame(jpeg, run_id)

    def _publish_frame(self, jpeg: bytes, run_id: str | None, only_first: bool = False) -> None:
        with self._frame_ready:
            if only_first and self._frame is not None:
                return  # a run's frame came first: it is newer than the idle home
            number = self._frame.number + 1 if self._frame is not None else 1
            frame = self._frame = CameraFrame(number, jpeg, run_id)
            self._frame_ready.notify_all()
        with self._guard:
            listeners = list(self._frame_listeners)
        for listener in listeners:
            try:
                listener(frame)
            except Exception:
                log.exception("camera frame listener failed")

    def _render_idle(self) -> None:
        """Render the home as it stands before any run: open a world, take one frame, close it."""
        from cbrs.kb.semantic_map import SemanticMap
        from cbrs.sim.world import open_world

        if not installed("sim"):
            return  # no simulated home, no camera frame
        with self._idle_render:
            if self._frame is not None or self.active() is not None or self.camera is None:
                return  # rendered meanwhile, or a run is about to give frames of its own
            try:
                with self.lock:
                    semantic_map = SemanticMap.read(self.kb)
                with open_world(seed=0, semantic_map=semantic_map) as world:
                    jpeg = _jpeg(world.camera(_view(world, self.camera)).capture().rgb)
            except Exception:
                log.exception("camera frame of the idle home failed")
                return
            self._publish_frame(jpeg, None, only_first=True)

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


def run_task(*args: Any, **kwargs: Any) -> RunResult:
    """:func:`cbrs.actions.runner.run_task`, imported with the first run: the planner and networkx stay
    out of ``cbrs serve``'s start-up."""
    from cbrs.actions.runner import run_task as run

    return run(*args, **kwargs)


def refusal_in_home(
    kb: KnowledgeBase, task: str, composer: Composer, transport: Transport | None = None
) -> RunResult | None:
    """The no-plan answer a run of ``task`` in the simulated home gives, found before the world is built
    (``actions.runner.refusal_before_world``, as ``cbrs run`` finds it); None when the world is needed.

    The world will implement what the simulation has skills for and what ``transport`` reaches, but for
    components whose own camera the map does not place. While the transport passes components over
    (their calls timed out, ``actions.breaker``), the run's answer names them: the world is built, as before.
    """
    from cbrs.actions.breaker import passed_over
    from cbrs.actions.runner import refusal_before_world
    from cbrs.sim.components import implementations
    from cbrs.sim.perceived import UNSEEN_AT_START
    from cbrs.sim.run_checks import map_bases, map_cameras, without_base, without_camera

    if transport is not None:
        sessions = {iri: state.registered_by for iri, state in kb.liveness.states().items()}
        if passed_over(transport, time.monotonic(), sessions):
            return None
    facts = kb.select("map_facts")  # read once for the cameras and the bases
    placed = map_cameras(kb, facts)
    bases = map_bases(kb, facts)
    ads = composer.advertisements
    runnable = set(implementations(kb, transport=transport, advertisements=ads).names())
    lacking = without_base(ads, bases)  # no mobile base, or several: its components cannot run, and the answer says so
    runnable -= set(without_camera(ads, placed)) | set(lacking)

    def why_not(advertisements: Sequence[Advertisement]) -> dict[str, str]:
        return {**without_camera(advertisements, placed), **without_base(advertisements, bases)}

    return refusal_before_world(kb, task, runnable, composer, why_not, lacking, UNSEEN_AT_START)


def _status(result: RunResult) -> str:
    """A finished run's status from its result: no-plan, cancelled, succeeded or failed."""
    from cbrs.actions.executor import RunStatus

    if result.report is None:
        return "no-plan"
    if result.report.status is RunStatus.CANCELLED:
        return "cancelled"
    return "succeeded" if result.succeeded else "failed"


def _jpeg(rgb: Any) -> bytes:
    from PIL import Image

    buffer = io.BytesIO()
    Image.fromarray(rgb).save(buffer, "JPEG", quality=JPEG_QUALITY)
    return buffer.getvalue()


PRECONDITIONS_NAMED = 3  # the most preconditions taken as given the line names; the run's JSON lists each


def preconditions_line(checks: Iterable[dict[str, Any]], listed: str = "--json lists each") -> str:
    """A run's ``preconditions`` (its JSON's ``{statement, believed}``: the task's own, as the run found
    them before its first step) in one line for a person, as ``cbrs run`` and the run page say them: those
    perceived holding counted, those no test decides (taken as given, as a fetch task's ``home:hasMarker``)
    named, at most ``PRECONDITIONS_NAMED``, then where the rest are ``listed`` (docs/execution.md, "A task's
    preconditions"); those a sensor read holding counted with what it read, and a precondition taken as
    given after a sensor was looked for with why none decided it, those the map's statements decided
    counted apart with what the map states; "" for none."""
    found = list(checks)
    held = sum(1 for check in found if check.get("believed") and not check.get("sensed"))
    read = [check for check in found if check.get("believed") and check.get("sensed")]
    sensed = [str(check["sensed"]) for check in read if not check.get("stated")]
    stated = [str(check["sensed"]) for check in read if check.get("stated")]
    given = [
        str(check.get("statement")) + (f" ({check['why']})" if check.get("why") else "")
        for check in found
        if check.get("believed") is None
    ]
    parts = [f"{held} perceived holding"] if held else []
    if sensed:
        parts.append(f"{len(sensed)} sensed holding ({'; '.join(sensed)})")
    if stated:
        parts.append(f"{len(stated)} holding by the map ({'; '.join(stated)})")
    if given:
        named = "; ".join(given[:PRECONDITIONS_NAMED])
        if len(given) > PRECONDITIONS_NAMED:
            named += f"; and {len(given) - PRECONDITIONS_NAMED} more ({listed})"
        parts.append(f"{len(given)} taken as given, no test decides {'it' if len(given) == 1 else 'them'}: {named}")
    return "preconditions: " + "; ".join(parts) if parts else ""


def check_choice(field: str, value: str, kind: type[Enum]) -> str:
    """``value`` when it names a member of ``kind`` (an option's choices), else :class:`RunOptionError`
    naming ``field`` and the choices: one set of words for a run's and a plan's options, wherever asked."""
    allowed = [member.value for member in kind]
    if value not in allowed:
        raise RunOptionError(field, value, "one of " + ", ".join(allowed))
    return value


def _check_options(objective: str, base_ties: str, near_misses: int | None) -> int:
    """The composition options checked as ``cbrs run`` checks its own (:class:`RunOptionError` naming the
    one at fault); returns ``near_misses``, ``ComposeConfig``'s default for None."""
    from cbrs.actions.base_choice import BaseTies
    from cbrs.actions.composer import Objective

    check_choice("objective", objective, Objective)
    check_choice("base_ties", base_ties, BaseTies)
    return check_near_misses(near_misses)


def check_near_misses(value: object) -> int:
    """``value`` when a whole number, 0 or more (how many components that come close to an unmet need a
    "no plan" answer names; 0: none), ``ComposeConfig``'s default for None, else :class:`RunOptionError`:
    one check for a run's ``near_misses`` and a plan's, wherever asked."""
    from cbrs.actions.composer import ComposeConfig

    if value is None:
        return ComposeConfig().near_misses
    if isinstance(value, bool) or not isinstance(value, int) or value < 0:
        raise RunOptionError("near_misses", value, "a whole number, 0 or more")
    return value


def _check_components(kb: KnowledgeBase, failing: tuple[str, ...]) -> None:
    if not failing:
        return
    from cbrs.sim.components import simulated

    known = set(simulated(kb))  # and the live components a run reaches over the bridge, as cbrs run --fail takes
    known |= {ad.iri for ad in kb.advertisements(include_unavailable=True) if ad.bridge_port is not None}
    unknown = [shorten(f) for f in failing if f not in known]
    if unknown:
        names = sorted(shorten(k) for k in known)
        raise UnknownComponentError(unknown, {u: difflib.get_close_matches(u, names, n=2) for u in unknown})
