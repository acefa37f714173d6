"""The query worker process: evaluates SPARQL queries on a read-only snapshot of the store.

Run by path (``python .../_query_worker.py PREFIXES STACK MEMORY``) by :mod:`cbrs.query_workers`, so it
imports nothing but the standard library and pyoxigraph and starts in a few tens of milliseconds. It
reads requests on stdin and answers on stdout; the parent kills it when a query outlasts its deadline
or its memory budget, which is the only way to stop an Oxigraph evaluation.
"""

from __future__ import annotations

import io
import json
import resource
import signal
import struct
import sys
import threading
import time
from typing import Any

import pyoxigraph as ox

REQUEST = struct.Struct(">I")
REPLY = struct.Struct(">cI")
OK, SYNTAX, EVALUATION, TOO_LARGE, NOT_ACCEPTABLE, LATE = b"K", b"S", b"E", b"L", b"N", b"T"


def dataset_options(dataset: dict[str, Any]) -> dict[str, Any]:
    """Oxigraph's ``Store.query`` options for a dataset as :func:`cbrs.sparql_service.dataset_for` decides it.

    ``{"union": true}``: no dataset was given, the default graph is the union of all graphs; otherwise
    ``default`` and ``named`` are IRI lists (protocol parameters, which override the query's FROM) or
    both absent (the query's own FROM / FROM NAMED, which Oxigraph applies). Shared by the endpoint's
    in-process evaluation, so both paths answer alike.
    """
    if dataset.get("union"):
        return {"use_default_graph_as_union": True}
    if dataset.get("default") is None and dataset.get("named") is None:
        return {}
    return {
        "default_graph": [ox.NamedNode(iri) for iri in dataset.get("default") or ()],
        "named_graphs": [ox.NamedNode(iri) for iri in dataset.get("named") or ()],
    }


class _Stop(Exception):
    def __init__(self, status: bytes) -> None:
        self.status = status


class _Budget(io.BytesIO):
    """Collects the serialised result, stopping at the byte limit or the deadline."""

    def __init__(self, limit: int, deadline: float) -> None:
        super().__init__()
        self.limit = limit
        self.deadline = deadline

    def write(self, data: Any) -> int:
        written = super().write(data)
        if self.tell() > self.limit:
            raise _Stop(TOO_LARGE)
        if time.monotonic() > self.deadline:
            raise _Stop(LATE)
        return written


class _Worker:
    def __init__(self, prefixes: dict[str, str]) -> None:
        self.prefixes = prefixes
        self.path: str | None = None
        self.store: ox.Store | None = None

    def open(self, path: str) -> ox.Store:
        if self.store is None or path != self.path:
            self.store = None  # release the old snapshot's files before opening the new one
            self.store = ox.Store.read_only(path)
            self.path = path
        return self.store

    def answer(self, request: dict[str, Any]) -> tuple[bytes, bytes]:
        deadline = time.monotonic() + float(request["seconds"])
        try:
            result = self.open(request["snapshot"]).query(
                request["text"], prefixes=self.prefixes, **dataset_options(request["dataset"])
            )
        except SyntaxError as error:
            return SYNTAX, str(error).encode()
        except (OSError, RuntimeError, ValueError) as error:
            return EVALUATION, str(error).encode()
        graph = isinstance(result, ox.QueryTriples)
        media = request["graph" if graph else "results"]
        if media is None:
            return NOT_ACCEPTABLE, b"graph" if graph else b"results"
        writer = _Budget(int(request["limit"]), deadline)
        try:
            if isinstance(result, ox.QueryTriples):
                result.serialize(writer, ox.RdfFormat.from_media_type(request["graph_format"]))
            else:
                result.serialize(writer, ox.QueryResultsFormat.from_media_type(request["results_format"]))
        except _Stop as stop:
            return stop.status, b""
        except (OSError, RuntimeError, ValueError) as error:  # evaluation is lazy: errors surface here
            return EVALUATION, str(error).encode()
        return OK, media.encode() + b"\0" + writer.getvalue()


def _limit_memory(budget: int) -> None:
    """Cap the address space at what the process maps now plus twice ``budget`` and 1 GiB (opening a
    snapshot reserves a few hundred MiB it never touches). The parent watches the resident size against
    ``budget``; this only stops an allocation that outruns the watch before it takes the machine."""
    try:
        with open("/proc/self/statm", encoding="ascii") as statm:
            size = int(statm.read().split()[0]) * resource.getpagesize()
        limit = size + 2 * budget + (1 << 30)
        resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    except (OSError, ValueError):
        pass


def _answer(worker: _Worker, request: dict[str, Any], outcome: list[tuple[bytes, bytes]]) -> None:
    outcome.append(worker.answer(request))


def main() -> None:
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is for the server; we end when stdin closes
    prefixes, stack, memory = json.loads(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3])
    threading.stack_size(stack)
    worker = _Worker(prefixes)
    requests, replies = sys.stdin.buffer, sys.stdout.buffer
    if memory > 0:
        _limit_memory(memory)
    replies.write(REPLY.pack(OK, 0))  # ready
    replies.flush()
    while True:
        header = requests.read(REQUEST.size)
        if len(header) < REQUEST.size:
            return
        (size,) = REQUEST.unpack(header)
        request = json.loads(requests.read(size))
        outcome: list[tuple[bytes, bytes]] = []
        thread = threading.Thread(target=_answer, args=(worker, request, outcome))
        thread.start()
        thread.join()
        status, payload = outcome[0] if outcome else (EVALUATION, b"the query worker failed")
        replies.write(REPLY.pack(status, len(payload)) + payload)
        replies.flush()


if __name__ == "__main__":
    main()
