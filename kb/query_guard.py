"""Isolating Oxigraph's SPARQL parser, so that no query or update text can take the process down.

Oxigraph parses, plans and evaluates recursively. A stack overflow in a Rust extension is not an
exception: it kills the whole process (the server, its bridge and every client with them). Bracket
nesting is one way to get there, but not the only one: a long chain of ``OPTIONAL``, ``BIND``,
``UNION`` or ``||`` builds an equally deep tree with no nesting at all. Rather than guess every such
construct, cbrs runs the text where a crash costs only that text:

1. A text of at most ``direct_chars`` characters (512 by default) goes straight to the store. The
   densest construct measured, nested function calls (``STR(STR(...``), needs about 1.7 KB of stack
   per character, so such a text needs at most about 0.85 MiB: under a ninth of the 8 MiB a thread
   gets by default (``bench/query_guard.py`` measures each construct).
2. A longer text is first run, parsed, planned and evaluated, on an empty in-memory store in a
   *checker* process whose working thread has ``check_stack`` (1 MiB) of stack, again an eighth of what
   the threads that really evaluate it get. If the checker dies, the text is refused with
   :class:`QueryTooComplexError` (HTTP 400) and the checker is replaced; this process never ran it.
   A text that passes is remembered (``remember`` texts, least recently used first out), so named and
   repeated queries are checked once.

The checker evaluates on an empty store, so what it runs is the parser and planner and the
evaluator's recursion over the plan, not the data. ``docs/security.md`` gives the measurements.
"""

from __future__ import annotations

import atexit
import contextlib
import hashlib
import os
import select
import signal
import struct
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import IO, Literal

from cbrs.kb.engine_faults import ErrorLog
from cbrs.kb.errors import EngineFaultError, QuerySyntaxError, QueryTooComplexError, StoreError
from cbrs.kb.recent_keys import RecentKeys

Kind = Literal["query", "update"]

DIRECT_CHARS = 512
CHECK_STACK = 1024 * 1024
CHECK_TIMEOUT = 10.0
CHECKERS = 2
REMEMBER = 4096
EVALUATION_STACK = 16 * 1024 * 1024
"""The stack cbrs gives the threads it starts to evaluate queries: twice a thread's usual 8 MiB."""

_SOLUTIONS_CHECKED = 10_000  # how many solutions the checker draws: enough to run the evaluator's recursion
_HEADER = struct.Struct(">cI")

# Replies of the checker: parsed (queries only, before evaluation), ok, syntax error, other error.
_PARSED, _OK, _SYNTAX, _ERROR = b"P", b"K", b"S", b"E"


class GuardBusyError(StoreError):
    """Every checker process is busy with another long text."""

    http_status = 503

    def __init__(self, checkers: int, seconds: float) -> None:
        super().__init__("query guard", f"all {checkers} query checkers stayed busy for {seconds:g} s; retry shortly")


class QueryGuard:
    """Admits a query or update text to the store only once it is known not to crash the process."""

    def __init__(
        self,
        direct_chars: int = DIRECT_CHARS,
        check_stack: int = CHECK_STACK,
        timeout: float = CHECK_TIMEOUT,
        checkers: int = CHECKERS,
        remember: int = REMEMBER,
    ) -> None:
        self.direct_chars = direct_chars
        self.check_stack = check_stack
        self.timeout = timeout
        self.checkers = checkers
        self.remember = remember
        self._admitted = RecentKeys()
        self._idle: list[_Checker] = []
        self._slots = threading.BoundedSemaphore(checkers)
        self._lock = threading.Lock()
        self.crashes = 0  # how many texts killed a checker: for tests and the log

    def admit(self, kind: Kind, text: str) -> None:
        """Return if ``text`` may run here; raise :class:`QueryTooComplexError` (or a syntax error) if not."""
        if len(text) <= self.direct_chars:
            return
        key = hashlib.blake2b(f"{kind}\0{text}".encode(), digest_size=16).digest()
        if self._admitted.seen(key):
            return
        self._check(kind, text)
        self._admitted.add(key, self.remember)

    def check(self, kind: Kind, text: str, wait: float | None = None) -> None:
        """Parse ``text`` (and evaluate it on an empty store) in a checker process whatever its length, for a
        caller that must not evaluate it in this process: Oxigraph evaluates an ASK, an aggregate or a
        ``SERVICE`` as it parses, and an empty store of the caller's own gave no deadline (the endpoint's
        busy path). ``wait``: seconds to wait for a free checker (default: the check's timeout), else
        :class:`GuardBusyError`; otherwise as :meth:`admit` refuses."""
        self._check(kind, text, wait)

    def close(self) -> None:
        """Stop the idle checker processes (busy ones stop when their check ends)."""
        with self._lock:
            idle, self._idle = self._idle, []
        for checker in idle:
            checker.stop()

    def _check(self, kind: Kind, text: str, wait: float | None = None) -> None:
        waited = self.timeout if wait is None else wait
        if not self._slots.acquire(timeout=waited):
            raise GuardBusyError(self.checkers, waited)
        checker: _Checker | None = None
        try:
            with self._lock:
                checker = self._idle.pop() if self._idle else None
            if checker is None or not checker.alive():
                checker = _Checker(self.check_stack)
            verdict = checker.check(kind, text, self.timeout)
            if verdict.crashed:
                self.crashes += 1
            if verdict.refusal is not None:
                raise verdict.refusal
        finally:
            if checker is not None and checker.alive():
                with self._lock:
                    self._idle.append(checker)
            elif checker is not None:
                checker.stop()
            self._slots.release()


class _Verdict:
    def __init__(self, refusal: Exception | None = None, crashed: bool = False) -> None:
        self.refusal = refusal
        self.crashed = crashed


class _Checker:
    """One checker process: reads texts from its stdin, answers on its stdout, dies instead of us."""

    def __init__(self, stack: int) -> None:
        package_root = str(Path(__file__).resolve().parents[1])
        env = dict(os.environ, PYTHONPATH=os.pathsep.join([package_root, os.environ.get("PYTHONPATH", "")]))
        command = [sys.executable, "-c", f"import {__name__} as guard; guard.serve_checks({stack})"]
        self.errors = ErrorLog()  # what it says as it dies tells a panic from a stack overflow
        self.process = subprocess.Popen(
            command, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=self.errors.file, env=env
        )
        _started.add(self.process)

    def alive(self) -> bool:
        return self.process.poll() is None

    def stop(self) -> None:
        _stop(self.process)
        _started.discard(self.process)
        self.errors.close()

    def check(self, kind: Kind, text: str, timeout: float) -> _Verdict:
        deadline = time.monotonic() + timeout
        payload = text.encode("utf-8", "surrogatepass")
        assert self.process.stdin is not None and self.process.stdout is not None
        try:
            self.process.stdin.write(_HEADER.pack(b"Q" if kind == "query" else b"U", len(payload)) + payload)
            self.process.stdin.flush()
        except (BrokenPipeError, OSError):
            return self._died(kind, text, parsed=False)
        parsed = False
        while True:
            try:
                status, message = _read_reply(self.process.stdout, deadline)
            except TimeoutError:
                self.stop()
                if parsed:  # it parsed and planned; evaluating it on an empty store is merely slow
                    return _Verdict()
                what = "query" if kind == "query" else "update"
                return _Verdict(QueryTooComplexError(text, f"the {what} could not be checked within {timeout:g} s"))
            except EOFError:
                return self._died(kind, text, parsed)
            if status == _PARSED:
                parsed = True
                continue
            if status == _SYNTAX:
                return _Verdict(QuerySyntaxError(text, message))
            return _Verdict()  # ok, or an evaluation error the real run will report in its own words

    def _died(self, kind: Kind, text: str, parsed: bool) -> _Verdict:
        try:
            code = self.process.wait(timeout=5)
        except subprocess.TimeoutExpired:
            code = None
        death = self.errors.death()
        self.stop()
        if death.panic is not None:  # the engine's own fault, which it named: not a text too deep
            return _Verdict(EngineFaultError(text, death.explain(), kind), crashed=True)
        how = f"signal {signal.Signals(-code).name}" if code is not None and code < 0 else f"exit status {code}"
        stage = "evaluating" if parsed else "parsing or planning"
        what = "query" if kind == "query" else "update"
        return _Verdict(
            QueryTooComplexError(
                text,
                f"the {what} crashed the store's SPARQL engine while {stage} it in an isolated checker ({how}): "
                "it is nested too deeply or chains too many operators or groups",
            ),
            crashed=True,
        )


def _read_exact(stream: IO[bytes], size: int, deadline: float) -> bytes:
    chunks = []
    fd = stream.fileno()
    while size:
        remaining = deadline - time.monotonic()
        if remaining <= 0:
            raise TimeoutError
        ready, _, _ = select.select([fd], [], [], remaining)
        if not ready:
            raise TimeoutError
        chunk = os.read(fd, size)
        if not chunk:
            raise EOFError
        chunks.append(chunk)
        size -= len(chunk)
    return b"".join(chunks)


def _read_reply(stream: IO[bytes], deadline: float) -> tuple[bytes, str]:
    status, size = _HEADER.unpack(_read_exact(stream, _HEADER.size, deadline))
    message = _read_exact(stream, size, deadline).decode("utf-8", "replace") if size else ""
    return status, message


_started: set[subprocess.Popen[bytes]] = set()


def _stop(process: subprocess.Popen[bytes]) -> None:
    if process.poll() is None:
        process.kill()
    with contextlib.suppress(subprocess.TimeoutExpired):  # a killed process that does not go away
        process.wait(timeout=5)
    for stream in (process.stdin, process.stdout):
        if stream is not None:
            stream.close()


_stack_lock = threading.Lock()


def start_evaluation_thread(thread: threading.Thread) -> None:
    """Start ``thread`` with :data:`EVALUATION_STACK` of stack, whatever the process's default."""
    with _stack_lock:
        previous = threading.stack_size(EVALUATION_STACK)
        try:
            thread.start()
        finally:
            threading.stack_size(previous)


@atexit.register
def _stop_all() -> None:
    for process in list(_started):
        _stop(process)


# -- the checker process -------------------------------------------------------------------------


def serve_checks(stack: int) -> None:
    """The checker's main loop: each text runs on a thread with ``stack`` bytes of stack."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is for the parent; we end when stdin closes
    requests, replies = sys.stdin.buffer, sys.stdout.buffer

    def reply(status: bytes, message: str = "") -> None:
        data = message.encode("utf-8", "replace")
        replies.write(_HEADER.pack(status, len(data)) + data)
        replies.flush()

    threading.stack_size(stack)
    while True:
        header = requests.read(_HEADER.size)
        if len(header) < _HEADER.size:
            return
        kind, size = _HEADER.unpack(header)
        text = requests.read(size).decode("utf-8", "surrogatepass")
        worker = threading.Thread(target=_run_check, args=(kind, text, reply))
        worker.start()
        worker.join()


def _run_check(kind: bytes, text: str, reply: Callable[[bytes, str], None]) -> None:
    import pyoxigraph as ox

    from cbrs.kb.namespaces import PREFIXES

    store = ox.Store()
    try:
        if kind == b"Q":
            result = store.query(text, prefixes=PREFIXES, use_default_graph_as_union=True)
            reply(_PARSED, "")
            if not isinstance(result, ox.QueryBoolean):
                for _count, _item in zip(range(_SOLUTIONS_CHECKED), result, strict=False):
                    pass
            del result
        else:
            store.update(text, prefixes=PREFIXES)
    except SyntaxError as error:
        reply(_SYNTAX, str(error))
        return
    except Exception as error:  # evaluation errors: not ours to judge; the real run reports them
        reply(_ERROR, str(error))
        return
    reply(_OK, "")
