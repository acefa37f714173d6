"""SPARQL queries evaluated in worker processes, so that a query past its deadline can be stopped.

Oxigraph has no way to interrupt an evaluation: a query computing an aggregate over a cartesian
product holds its thread (and a core, and a growing amount of memory) until it ends, however long
that is, and a thread cannot be killed from Python. A process can. So the endpoint evaluates each
query in one of a few worker processes (:mod:`cbrs._query_worker`) on a read-only snapshot of the
store, and kills the worker when the query outlasts ``timeout`` or its resident memory passes
``memory``: the core and the memory are back at once, the slot is free, and a fresh worker starts.

A snapshot is a RocksDB checkpoint of the store (hard links to its immutable files, made in tens of
milliseconds), taken when a query finds the store written since the last one, so a query always sees
every write that came before it. A snapshot no worker reads and that is not the newest is deleted.
An in-memory store has no files to link: its snapshot is a copy of its quads into an on-disk store
(Oxigraph's bulk loader, some ten thousand quads in a few tens of milliseconds), made under the same
rule, so its cost grows with the store; ``cbrs serve`` isolates an in-memory store this way
(``EndpointConfig.isolate_memory``), the library's default is threads.

A worker left idle for ``idle`` seconds (setting ``query_worker_idle``) is stopped, so that a server
that answered a heavy query an hour ago does not hold a process and its memory for it; the next query
that needs one starts a worker again (a few tens of milliseconds).
"""

from __future__ import annotations

import atexit
import contextlib
import json
import logging
import os
import re
import secrets
import select
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from cbrs.kb.engine_faults import ErrorLog
from cbrs.kb.errors import (
    EngineFaultError,
    KnowledgeBaseError,
    QuerySyntaxError,
    QueryTooComplexError,
    StoreEvaluationError,
)
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.query_guard import EVALUATION_STACK
from cbrs.kb.store import EmbeddedStore

log = logging.getLogger("cbrs.query_workers")

_SCRIPT = Path(__file__).with_name("_query_worker.py")
_REQUEST = struct.Struct(">I")
_REPLY = struct.Struct(">cI")
_WATCH = 0.05  # seconds between two looks at a busy worker's resident memory
_START = 20.0  # seconds a new worker may take to say it is ready
_PAGE = os.sysconf("SC_PAGE_SIZE") if hasattr(os, "sysconf") else 4096


class QueryStopped(KnowledgeBaseError):
    """A query the endpoint stopped: ``reason`` is ``timeout``, ``memory``, ``too-large`` or ``not-acceptable``."""

    def __init__(self, reason: str, detail: str = "") -> None:
        self.reason = reason
        super().__init__(detail or reason)


@dataclass(frozen=True)
class Request:
    text: str
    results_type: str | None  # the media type to answer a SELECT or ASK in; None: not acceptable
    graph_type: str | None  # likewise for CONSTRUCT and DESCRIBE
    results_format: str  # the canonical media type of the serialiser for each
    graph_format: str
    limit: int
    timeout: float
    dataset: Mapping[str, Any] = field(default_factory=lambda: {"union": True})  # see _query_worker.dataset_options


class _Snapshot:
    def __init__(self, path: Path, generation: int) -> None:
        self.path = path
        self.generation = generation
        self.readers = 0


class _Process:
    """One worker process and the snapshot it has open."""

    def __init__(self, stack: int, memory: int) -> None:
        command = [sys.executable, str(_SCRIPT), json.dumps(PREFIXES), str(stack), str(memory)]
        self.errors = ErrorLog()  # what it says as it dies tells a panic from an allocation past the cap
        self.popen = subprocess.Popen(
            command, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=self.errors.file, start_new_session=True
        )
        self.ready = False
        self.snapshot: _Snapshot | None = None
        self.idle_since = time.monotonic()
        _started.add(self.popen)

    def alive(self) -> bool:
        return self.popen.poll() is None

    def resident(self) -> int:
        try:
            with open(f"/proc/{self.popen.pid}/statm", encoding="ascii") as statm:
                return int(statm.read().split()[1]) * _PAGE
        except (OSError, ValueError, IndexError):
            return 0

    def kill(self) -> None:
        _stop(self.popen)
        _started.discard(self.popen)
        self.errors.close()


class QueryProcesses:
    """Up to ``size`` worker processes evaluating queries on snapshots of ``store``."""

    def __init__(
        self, store: EmbeddedStore, size: int, memory: int, stack: int = EVALUATION_STACK, idle: float = 30.0
    ) -> None:
        self.store = store
        self.size = size
        self.memory = memory
        self.stack = stack
        self.idle = idle
        self.killed = 0  # workers killed for a deadline or memory: for tests and the log
        self._idle: list[_Process] = []
        self._lock = threading.Lock()
        self._snapshot_lock = threading.Lock()
        self._current: _Snapshot | None = None
        self._count = 0
        self._closed = False
        self._reaper: threading.Thread | None = None
        self._wake = threading.Event()
        owner = _owner(store)
        try:  # beside the store, so the checkpoint hard-links its files instead of copying them
            if store.in_memory:
                raise OSError("an in-memory store's snapshots are copies: the temporary folder will do")
            self._root = _snapshot_root(Path(store.location).resolve().parent, "." + SNAPSHOTS, owner)
        except OSError:
            self._root = _snapshot_root(Path(tempfile.gettempdir()), SNAPSHOTS, owner)

    def run(self, request: Request) -> tuple[bytes, str]:
        """Evaluate ``request`` in a worker; (body, media type), or an error the endpoint reports."""
        snapshot = self._fresh()  # reserved for this request: no later write's snapshot deletes it
        try:
            worker = self._take()
        except BaseException:
            self._unreserve(snapshot)
            raise
        deadline = time.monotonic() + request.timeout
        try:
            self._hold(worker, snapshot)
            payload = json.dumps(
                {
                    "snapshot": str(snapshot.path),
                    "text": request.text,
                    "results": request.results_type,
                    "graph": request.graph_type,
                    "results_format": request.results_format,
                    "graph_format": request.graph_format,
                    "limit": request.limit,
                    "seconds": request.timeout,
                    "dataset": dict(request.dataset),
                }
            ).encode("utf-8", "surrogatepass")
            assert worker.popen.stdin is not None
            worker.popen.stdin.write(_REQUEST.pack(len(payload)) + payload)
            worker.popen.stdin.flush()
            status, body = self._reply(worker, deadline)
        except BaseException:
            self._discard(worker)
            raise
        self._give_back(worker)
        return self._outcome(request, status, body)

    def close(self) -> None:
        """Stop every idle worker and delete the snapshots (busy workers are killed when their query ends)."""
        with self._lock:
            self._closed = True
            idle, self._idle = self._idle, []
        self._wake.set()
        for worker in idle:
            worker.kill()
        shutil.rmtree(self._root, ignore_errors=True)
        _roots.discard(self._root)

    # -- snapshots -------------------------------------------------------------------------------------

    def _fresh(self) -> _Snapshot:
        """The snapshot of the store as it is now, reserved (counted as read) for the caller, who hands the
        reservation to a worker (:meth:`_hold`) or gives it up (:meth:`_unreserve`). Reserved here, under the
        lock that makes snapshots, so a write's next snapshot cannot delete it while the caller starts a
        worker (tens of milliseconds), which it did when writes came faster than that."""
        with self._snapshot_lock:
            generation = self.store.generation
            current = self._current
            fresh = current
            if fresh is None or fresh.generation != generation:
                self._count += 1
                path = self._root / f"snapshot-{self._count}"
                self.store.snapshot(path)
                fresh = self._current = _Snapshot(path, generation)
            with self._lock:
                fresh.readers += 1
                if current is not None and current is not fresh and current.readers == 0:
                    shutil.rmtree(current.path, ignore_errors=True)
            return fresh

    def _unreserve(self, snapshot: _Snapshot) -> None:
        """Give up a reservation :meth:`_fresh` made that no worker took."""
        with self._lock:
            snapshot.readers -= 1
            if snapshot.readers == 0 and snapshot is not self._current:
                shutil.rmtree(snapshot.path, ignore_errors=True)

    def _hold(self, worker: _Process, snapshot: _Snapshot) -> None:
        """``worker`` now reads ``snapshot``, taking over the reservation :meth:`_fresh` made for it."""
        with self._lock:
            self._release(worker)
            worker.snapshot = snapshot

    def _release(self, worker: _Process) -> None:
        """Called with ``_lock`` held: ``worker`` no longer reads its snapshot."""
        old, worker.snapshot = worker.snapshot, None
        if old is None:
            return
        old.readers -= 1
        if old.readers == 0 and old is not self._current:
            shutil.rmtree(old.path, ignore_errors=True)

    # -- workers ---------------------------------------------------------------------------------------

    def _take(self) -> _Process:
        with self._lock:
            while self._idle:
                worker = self._idle.pop()
                if worker.alive():
                    return worker
                self._release(worker)
                worker.kill()
        worker = _Process(self.stack, self.memory)
        try:
            status, _ = self._reply(worker, time.monotonic() + _START, starting=True)
        except BaseException:
            worker.kill()
            raise
        worker.ready = status == b"K"
        return worker

    def _give_back(self, worker: _Process) -> None:
        with self._lock:
            if not self._closed and len(self._idle) < self.size:
                worker.idle_since = time.monotonic()
                self._idle.append(worker)
                if self._reaper is None:
                    self._reaper = threading.Thread(target=self._reap, name="cbrs-query-reaper", daemon=True)
                    self._reaper.start()
                return
            self._release(worker)
        worker.kill()

    def _reap(self) -> None:
        """Stop the workers idle for longer than ``idle`` seconds, until closed."""
        while not self._wake.wait(max(0.05, min(self.idle / 2, 5.0))):
            cutoff = time.monotonic() - self.idle
            with self._lock:
                stale = [worker for worker in self._idle if worker.idle_since <= cutoff]
                self._idle = [worker for worker in self._idle if worker.idle_since > cutoff]
                for worker in stale:
                    self._release(worker)
            for worker in stale:
                worker.kill()

    def _discard(self, worker: _Process) -> None:
        with self._lock:
            self._release(worker)
        worker.kill()

    def _spare(self) -> None:
        """Start a worker in the background to replace a killed one, so the next query need not wait."""
        with self._lock:
            if self._closed or len(self._idle) >= self.size:
                return

        def start() -> None:
            try:
                worker = _Process(self.stack, self.memory)
                self._reply(worker, time.monotonic() + _START, starting=True)
            except Exception:  # no spare then: the next query starts its own worker
                return
            self._give_back(worker)

        threading.Thread(target=start, name="cbrs-query-worker-start", daemon=True).start()

    def _reply(self, worker: _Process, deadline: float, starting: bool = False) -> tuple[bytes, bytes]:
        """The worker's answer; kills it at ``deadline`` or when it holds more than ``memory``."""
        stdout = worker.popen.stdout
        assert stdout is not None
        buffer = bytearray()  # grown in place: a bytes object copied whole per 64 KiB read took 19 s for 33 MB
        needed = _REPLY.size
        header: tuple[bytes, int] | None = None
        fd = stdout.fileno()
        while True:
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                self._stop(worker, "timeout")
                raise QueryStopped("timeout")
            ready, _, _ = select.select([fd], [], [], min(_WATCH, remaining))
            if not ready:
                if not starting and self.memory > 0 and worker.resident() > self.memory:
                    self._stop(worker, "memory")
                    raise QueryStopped("memory")
                continue
            chunk = os.read(fd, max(65536, needed - len(buffer)))
            if not chunk:
                raise self._died(worker, starting)
            buffer += chunk
            if header is None and len(buffer) >= _REPLY.size:
                header = _REPLY.unpack(buffer[: _REPLY.size])
                del buffer[: _REPLY.size]
                needed = header[1]
            if header is not None and len(buffer) >= needed:
                return header[0], bytes(buffer[:needed])

    def _stop(self, worker: _Process, why: str) -> None:
        self.killed += 1
        log.info("query worker %d killed: %s", worker.popen.pid, why)
        self._discard(worker)
        self._spare()

    def _died(self, worker: _Process, starting: bool) -> KnowledgeBaseError:
        try:
            code = worker.popen.wait(timeout=5)
        except subprocess.TimeoutExpired:
            code = None
        death = worker.errors.death()
        self._discard(worker)
        self._spare()
        how = f"signal {signal.Signals(-code).name}" if code is not None and code < 0 else f"exit status {code}"
        if death.panic is not None and not starting:  # the engine named its own fault: not the memory cap
            return EngineFaultError("", death.explain())  # the endpoint knows the text
        if code == -signal.SIGABRT and self.memory > 0:  # an allocation past the address-space cap aborts
            return QueryStopped("memory")
        if starting:
            return StoreEvaluationError(self.store.location, "query", f"a query worker could not start ({how})")
        return QueryTooComplexError(
            "", f"the query ended its worker process ({how}): it crashed the SPARQL engine or ran out of memory"
        )

    def _outcome(self, request: Request, status: bytes, body: bytes) -> tuple[bytes, str]:
        message = body.decode("utf-8", "replace")
        if status == b"K":
            media, _, result = body.partition(b"\0")
            return result, media.decode("ascii")
        if status == b"S":
            raise QuerySyntaxError(request.text, message)
        if status == b"E":
            raise StoreEvaluationError(self.store.location, "query", message)
        if status == b"L":
            raise QueryStopped("too-large")
        if status == b"T":
            raise QueryStopped("timeout")
        if status == b"N":
            raise QueryStopped("not-acceptable", message)
        raise StoreEvaluationError(self.store.location, "query", f"unexpected worker answer {status!r}")


_started: set[subprocess.Popen[bytes]] = set()
_roots: set[Path] = set()
_roots_lock = threading.Lock()  # a root is made and counted as this process's in one step

SNAPSHOTS = "cbrs-query-snapshots-"
"""How a folder of query snapshots is named: ``.cbrs-query-snapshots-STORE-PID-XXXXXXXX`` beside the store
directory STORE (``cbrs-query-snapshots-...`` in the temporary folder for an in-memory store, ``memory``,
or when the store's folder takes none), PID the process that made it. A process killed with SIGKILL
leaves it behind, holding hard links to store files the store has since compacted away; the next process
to snapshot the same store removes every such folder whose process has ended (:func:`_remove_left`)."""
_OWNER_LENGTH = 100  # of a store's name in the folder's: a folder name is at most 255 bytes


def _owner(store: EmbeddedStore) -> str:
    """The store's name as its snapshots' folder carries it: its directory's, or ``memory``."""
    return "memory" if store.in_memory else Path(store.location).name[:_OWNER_LENGTH] or "store"


def _snapshot_root(parent: Path, prefix: str, owner: str) -> Path:
    """A new folder for this process's snapshots of ``owner`` in ``parent``, after removing those a process
    that ended left there."""
    with _roots_lock:
        _remove_left(parent, prefix + owner)
        while True:
            root = parent / f"{prefix}{owner}-{os.getpid()}-{secrets.token_hex(4)}"
            try:
                root.mkdir(mode=0o700)
            except FileExistsError:
                continue
            _roots.add(root)
            return root


def _remove_left(parent: Path, stem: str) -> None:
    """Remove the folders ``stem-PID-XXXXXXXX`` in ``parent`` whose process PID has ended (or is this one,
    which made it before: a service restarted in a container often gets its old PID, and this process's
    own live folders are in ``_roots``). A live process's folder is never touched: a PID taken since by
    another process keeps its folder until that one ends too."""
    pattern = re.compile(re.escape(stem) + r"-(\d+)-[0-9a-f]{8}")
    try:
        names = [entry.name for entry in os.scandir(parent) if entry.is_dir(follow_symlinks=False)]
    except OSError:
        return
    for name in names:
        matched = pattern.fullmatch(name)
        if matched is None:
            continue
        path = parent / name
        pid = int(matched.group(1))
        if path in _roots or (pid != os.getpid() and _alive(pid)):
            continue
        log.info("removing %s, query snapshots left by process %d, which has ended", path, pid)
        shutil.rmtree(path, ignore_errors=True)


def _alive(pid: int) -> bool:
    """Whether process ``pid`` exists (another user's too: signal 0 is refused to it, not unknown)."""
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    except (OSError, OverflowError):  # a PID past the system's range: no process has it
        return False
    return True


def _stop(process: subprocess.Popen[bytes]) -> None:
    if process.poll() is None:
        process.kill()
    with contextlib.suppress(subprocess.TimeoutExpired):
        process.wait(timeout=5)
    for stream in (process.stdin, process.stdout):
        if stream is not None:
            with contextlib.suppress(OSError):
                stream.close()


@atexit.register
def _stop_all() -> None:
    for process in list(_started):
        _stop(process)
    for root in list(_roots):
        shutil.rmtree(root, ignore_errors=True)
