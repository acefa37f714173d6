"""Concurrent load on a running cbrs server over loopback, shared by tests/test_concurrency.py (which
checks what it records) and bench/concurrency.py (which prints its figures).

- :func:`sparql_load`: readers querying ``/sparql`` while one writer sends ``INSERT DATA`` batches to
  ``/update``, for a bounded time. Batch ``i`` adds ``batch`` triples ``<urn:conc:i-j> <urn:conc:batch> i``,
  so any snapshot of a store the writer alone changes holds batches ``0..k`` whole: ``COUNT`` is
  ``batch * (MAX + 1)``.
- :func:`bridge_load`: publishers on a few topics, each with subscribers, over rosbridge websockets, for a
  bounded time. A pass-through subscriber is promised every message published after its subscribe was
  handled, in order per publisher, unless it falls more than ``max_queue_length`` (1000) messages behind
  on a topic (cbrs/rosbridge/outbox.py). Publishers hold back while any subscriber of their topic is
  ``window`` messages behind, so that limit is never reached and every message is owed.

Every loop ends at its deadline; every socket wait has a timeout.
"""

from __future__ import annotations

import json
import threading
import time
from collections import defaultdict
from collections.abc import Callable
from contextlib import ExitStack
from dataclasses import dataclass, field
from typing import Any

import httpx
from websockets.sync.client import ClientConnection, connect

WAIT = 10.0  # bound on any one request, and on draining the subscribers at the end
GRAPH = "urn:conc:writes"
BATCH_QUERY = f"SELECT (COUNT(?s) AS ?n) (MAX(?b) AS ?last) WHERE {{ GRAPH <{GRAPH}> {{ ?s <urn:conc:batch> ?b }} }}"
SPLIT_VARIABLES = ("inputs", "outputs")  # GROUP_CONCAT values: their order is not part of the answer


@dataclass
class SparqlLoad:
    """What the readers saw and the writer committed."""

    batch: int
    counts: list[list[tuple[int, int]]]  # per reader, in order: (COUNT, MAX batch or -1)
    stable: list[list[str]]  # per reader, the stable query's answers, canonicalised
    read_latencies: list[float] = field(default_factory=list)
    update_latencies: list[float] = field(default_factory=list)
    committed: int = 0
    busy: int = 0  # 503 {"error": "busy"}: every query worker was taken (documented, docs/serving.md)
    errors: list[str] = field(default_factory=list)  # anything else that was not an answer
    seconds: float = 0.0


def insert_batch(index: int, batch: int) -> str:
    triples = "".join(f"<urn:conc:{index}-{j}> <urn:conc:batch> {index} . " for j in range(batch))
    return f"INSERT DATA {{ GRAPH <{GRAPH}> {{ {triples}}} }}"


def canonical(body: dict[str, Any]) -> str:
    """A SELECT answer as text that does not depend on row order or GROUP_CONCAT order."""
    rows = []
    for binding in body["results"]["bindings"]:
        row = {}
        for name, term in binding.items():
            value = term["value"]
            row[name] = " ".join(sorted(value.split())) if name in SPLIT_VARIABLES else value
        rows.append(json.dumps(row, sort_keys=True))
    return "\n".join(sorted(rows))


def batches_seen(body: dict[str, Any]) -> tuple[int, int]:
    (row,) = body["results"]["bindings"]
    return int(row["n"]["value"]), int(row["last"]["value"]) if "last" in row else -1


def sparql_load(base: str, token: str, readers: int, seconds: float, stable_query: str, batch: int) -> SparqlLoad:
    """``readers`` threads alternate :data:`BATCH_QUERY` and ``stable_query`` on ``base/sparql`` while one
    writes batches to ``base/update`` with ``token``, all for ``seconds``."""
    load = SparqlLoad(batch, [[] for _ in range(readers)], [[] for _ in range(readers)])
    lock = threading.Lock()
    deadline = time.monotonic() + seconds

    def failed(what: str) -> None:
        with lock:
            load.errors.append(what)

    def read(index: int) -> None:
        with httpx.Client(timeout=WAIT) as client:
            turn = index

            def going() -> bool:  # past the deadline, until it has an answer of each kind (bounded): on a
                # loaded machine a reader's first answer came after the deadline, and it had nothing to check
                now = time.monotonic()
                answered = bool(load.counts[index]) and bool(load.stable[index])
                return now < deadline or (now < deadline + WAIT and not answered)

            while going():
                query = BATCH_QUERY if turn % 2 == 0 else stable_query
                start = time.perf_counter()
                try:
                    response = client.post(
                        base + "/sparql",
                        content=query.encode("utf-8"),
                        headers={
                            "Content-Type": "application/sparql-query",
                            "Accept": "application/sparql-results+json",
                        },
                    )
                except httpx.HTTPError as error:
                    failed(f"reader {index}: {type(error).__name__}: {error}")
                    continue
                if response.status_code == 503 and response.json().get("error") == "busy":
                    with lock:
                        load.busy += 1
                    continue
                if response.status_code != 200:
                    failed(f"reader {index}: HTTP {response.status_code}: {response.text[:200]}")
                    continue
                with lock:
                    load.read_latencies.append(time.perf_counter() - start)
                if query is BATCH_QUERY:
                    load.counts[index].append(batches_seen(response.json()))
                else:
                    load.stable[index].append(canonical(response.json()))
                turn += 1

    def write() -> None:
        headers = {"Content-Type": "application/sparql-update", "Authorization": f"Bearer {token}"}
        with httpx.Client(timeout=WAIT) as client:
            while time.monotonic() < deadline:
                start = time.perf_counter()
                try:
                    response = client.post(
                        base + "/update", content=insert_batch(load.committed, batch), headers=headers
                    )
                except httpx.HTTPError as error:
                    failed(f"writer: {type(error).__name__}: {error}")
                    return  # the batch may or may not be in: the count check would be meaningless
                if response.status_code != 204:
                    failed(f"writer: HTTP {response.status_code}: {response.text[:200]}")
                    return
                load.update_latencies.append(time.perf_counter() - start)
                load.committed += 1

    _join(_start([lambda i=i: read(i) for i in range(readers)] + [write], load.errors, lock), seconds + WAIT)
    load.seconds = seconds
    return load


@dataclass
class BridgeLoad:
    """What each publisher sent and each subscriber received, per publisher in arrival order."""

    topics: list[str]
    publisher_topics: list[str]  # publisher p publishes on publisher_topics[p]
    subscriber_topics: list[list[str]]  # subscriber s listens to these
    published: list[int] = field(default_factory=list)
    received: list[dict[int, list[int]]] = field(default_factory=list)
    errors: list[str] = field(default_factory=list)
    seconds: float = 0.0  # from the first publish to the last message received


class _Flow:
    """Publishers of one topic wait while any of its subscribers is ``window`` messages behind."""

    def __init__(self, subscribers: list[int], window: int) -> None:
        self.window = window
        self.sent = 0
        self.arrivals = dict.fromkeys(subscribers, 0)
        self.changed = threading.Condition()

    def take(self, deadline: float) -> bool:
        """Wait (until ``deadline`` at most) for room to send one more; False if there was none."""
        with self.changed:
            room = self.changed.wait_for(
                lambda: self.sent - min(self.arrivals.values()) < self.window, max(0.0, deadline - time.monotonic())
            )
            if room:
                self.sent += 1
            return room

    def arrived(self, subscriber: int) -> None:
        with self.changed:
            self.arrivals[subscriber] += 1
            self.changed.notify_all()


def send(ws: ClientConnection, **message: Any) -> None:
    ws.send(json.dumps(message))


def sync(ws: ClientConnection) -> None:
    """Return once the server has handled everything ``ws`` sent before (bounded)."""
    send(ws, op="call_service", service="/rosapi/get_time", id="sync")
    deadline = time.monotonic() + WAIT
    while json.loads(ws.recv(timeout=max(0.01, deadline - time.monotonic()))).get("id") != "sync":
        pass


def bridge_load(
    url: str, publishers: int, topics: int, subscribers_per_topic: int, seconds: float, window: int = 500
) -> BridgeLoad:
    """``publishers`` connections publish ``{p, n}`` round-robin over ``topics`` topics for ``seconds``; each
    topic has ``subscribers_per_topic`` subscribers of its own, and one more connection subscribes to every
    topic (to the first one twice: rosbridge merges the two, and each message must come once)."""
    names = [f"/conc/topic{k}" for k in range(topics)]
    heard = [[name] for name in names for _ in range(subscribers_per_topic)] + [names]
    load = BridgeLoad(names, [names[p % topics] for p in range(publishers)], heard, [0] * publishers)
    load.received = [defaultdict(list) for _ in heard]
    with ExitStack() as stack:
        run = _BridgeRun(
            load,
            [stack.enter_context(connect(url, open_timeout=WAIT, close_timeout=WAIT)) for _ in range(publishers)],
            [stack.enter_context(connect(url, open_timeout=WAIT, close_timeout=WAIT)) for _ in heard],
            window,
        )
        run.subscribe_all()
        subscribers = _start([lambda s=s: run.listen(s, seconds) for s in range(len(heard))], load.errors, run.lock)
        publishing = _start([lambda p=p: run.publish(p, seconds) for p in range(publishers)], load.errors, run.lock)
        _join(publishing, seconds + WAIT)
        run.drained.set()
        _join(subscribers, seconds + 2 * WAIT)
        load.seconds = run.last_receive - min(run.first_publish, default=run.last_receive)
    return load


class _BridgeRun:
    """The connections of one :func:`bridge_load` and what its threads share."""

    def __init__(
        self, load: BridgeLoad, talkers: list[ClientConnection], listeners: list[ClientConnection], window: int
    ) -> None:
        self.load, self.talkers, self.listeners = load, talkers, listeners
        self.flows = {
            name: _Flow([s for s, heard in enumerate(load.subscriber_topics) if name in heard], window)
            for name in load.topics
        }
        self.lock = threading.Lock()
        self.go = threading.Barrier(len(talkers) + len(listeners))  # everyone starts together
        self.drained = threading.Event()  # every publisher stopped: listeners then read what is owed
        self.first_publish: list[float] = []
        self.last_receive = 0.0

    def subscribe_all(self) -> None:
        """Subscribe every listener and advertise every talker, each handled by the server before returning."""
        for s, (ws, heard) in enumerate(zip(self.listeners, self.load.subscriber_topics, strict=True)):
            for name in heard:
                send(ws, op="subscribe", topic=name, type="conc/Count", id=f"{s}:{name}")
            if len(heard) > 1:
                send(ws, op="subscribe", topic=heard[0], type="conc/Count", id=f"{s}:again")
            sync(ws)
        for ws, name in zip(self.talkers, self.load.publisher_topics, strict=True):
            send(ws, op="advertise", topic=name, type="conc/Count")
            sync(ws)

    def publish(self, p: int, seconds: float) -> None:
        ws, name = self.talkers[p], self.load.publisher_topics[p]
        self.go.wait(WAIT)
        with self.lock:
            self.first_publish.append(time.perf_counter())
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline and self.flows[name].take(deadline):
            send(ws, op="publish", topic=name, msg={"p": p, "n": self.load.published[p]})
            self.load.published[p] += 1

    def listen(self, s: int, seconds: float) -> None:
        ws, got = self.listeners[s], self.load.received[s]
        self.go.wait(WAIT)
        hard_stop = time.monotonic() + seconds + WAIT
        while time.monotonic() < hard_stop:
            if self.drained.is_set() and sum(map(len, got.values())) >= self.owed(s):
                return
            try:
                message = json.loads(ws.recv(timeout=0.1))
            except TimeoutError:
                continue
            if message.get("op") != "publish":
                with self.lock:
                    self.load.errors.append(f"subscriber {s} got {message}")
                continue
            got[message["msg"]["p"]].append(message["msg"]["n"])
            self.flows[message["topic"]].arrived(s)
            with self.lock:
                self.last_receive = max(self.last_receive, time.perf_counter())

    def owed(self, s: int) -> int:
        heard = self.load.subscriber_topics[s]
        return sum(n for p, n in enumerate(self.load.published) if self.load.publisher_topics[p] in heard)


def _start(work: list[Callable[[], None]], errors: list[str], lock: threading.Lock) -> list[threading.Thread]:
    """Run each callable on its own thread; an exception it raises becomes an error line."""

    def guarded(job: Callable[[], None]) -> None:
        try:
            job()
        except Exception as error:  # recorded, so the caller's assertion shows it
            with lock:
                errors.append(f"{type(error).__name__}: {error}")

    threads = [threading.Thread(target=guarded, args=(job,)) for job in work]
    for thread in threads:
        thread.start()
    return threads


def _join(threads: list[threading.Thread], timeout: float) -> None:
    deadline = time.monotonic() + timeout
    for thread in threads:
        thread.join(max(0.0, deadline - time.monotonic()))
