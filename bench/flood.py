"""Benchmark: one client floods a `cbrs serve`; another client's point lookups must keep being answered.

Run: python bench/flood.py [--seconds S] [--anchor-seconds A] [--timeout T]

A `cbrs serve` child process holds a fresh seeded store on disk (query timeout T, the other limits at
their defaults). The victim, on 127.0.0.1, sends point lookups one after another: on HTTP (`/sparql`, an
ASK on one IRI) and on the bridge (`/cbrs/query`, the same text). First alone for A seconds (the
anchor), then for S seconds while the flooder, bound to 127.0.0.2 (another client to the server),
keeps four heavy queries going (a COUNT over a three-way cartesian product: ~1e11 solutions, it never
ends by itself), opens 32 event streams and holds them, and opens 200 bridge connections, each
subscribed to /cbrs/events, 8 of them also sending the heavy query on /cbrs/query in a loop.

Prints the machine, the inputs, the victim's answered share and latency percentiles alone and under
the flood, their ratio, and what the flood got (heavy queries stopped, refusals, streams and
connections admitted). Everything is on loopback; every loop ends at its deadline.
"""

from __future__ import annotations

import argparse
import asyncio
import contextlib
import json
import os
import platform
import re
import signal
import statistics
import subprocess
import sys
import tempfile
import threading
import time
from collections import Counter
from pathlib import Path
from typing import Any

import httpx
from websockets.asyncio.client import connect

HEAVY = "SELECT (COUNT(*) AS ?n) WHERE { ?a ?b ?c . ?d ?e ?f . ?g ?h ?i }"
POINT = "ASK { GRAPH ?g { <https://w3id.org/cbrs/core#hasPort> ?p ?o } }"
FLOODER, VICTIM = "127.0.0.2", "127.0.0.1"


def start_server(folder: Path, timeout: float) -> tuple[subprocess.Popen[str], int, int]:
    env = dict(os.environ, CBRS_QUERY_TIMEOUT=str(timeout), PYTHONUNBUFFERED="1")
    command = [
        sys.executable,
        "-m",
        "cbrs",
        "--store",
        str(folder / "store"),
        "serve",
        "--port",
        "0",
        "--bridge-port",
        "0",
    ]
    child = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True, env=env)
    assert child.stdout is not None
    http = bridge = 0
    deadline = time.monotonic() + 60
    while (not http or not bridge) and time.monotonic() < deadline:
        line = child.stdout.readline()
        if not line:
            break
        if match := re.search(r"http://[^:]+:(\d+)/sparql", line):
            http = int(match.group(1))
        if match := re.search(r"ws://[^:]+:(\d+)", line):
            bridge = int(match.group(1))
    if not http or not bridge:
        child.kill()
        raise SystemExit("cbrs serve did not start within 60 s")
    threading.Thread(target=lambda: [None for _ in child.stdout or ()], daemon=True).start()  # drain
    return child, http, bridge


class Victim:
    """Point lookups, one after another, on HTTP and on the bridge, until ``stop``."""

    def __init__(self, http: int, bridge: int) -> None:
        self.http, self.bridge = http, bridge
        self.latencies: dict[str, list[float]] = {"http": [], "bridge": []}
        self.failures: Counter[str] = Counter()

    def run(self, seconds: float) -> None:
        deadline = time.monotonic() + seconds
        threads = [
            threading.Thread(target=self._http, args=(deadline,)),
            threading.Thread(target=lambda: asyncio.run(self._bridge(deadline))),
        ]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join(seconds + 30)

    def _http(self, deadline: float) -> None:
        transport = httpx.HTTPTransport(local_address=VICTIM)
        with httpx.Client(transport=transport, timeout=10.0) as client:
            url = f"http://127.0.0.1:{self.http}/sparql"
            while time.monotonic() < deadline:
                started = time.perf_counter()
                try:
                    response = client.get(url, params={"query": POINT})
                    ok = response.status_code == 200 and response.json()["boolean"] is True
                    reason = str(response.status_code)
                except httpx.HTTPError as error:
                    ok, reason = False, type(error).__name__
                if ok:
                    self.latencies["http"].append(time.perf_counter() - started)
                else:
                    self.failures[f"http {reason}"] += 1

    async def _bridge(self, deadline: float) -> None:
        async with connect(f"ws://127.0.0.1:{self.bridge}", open_timeout=10, local_addr=(VICTIM, 0)) as ws:
            number = 0
            while time.monotonic() < deadline:
                number += 1
                started = time.perf_counter()
                call = {"op": "call_service", "id": str(number), "service": "/cbrs/query", "args": {"query": POINT}}
                await ws.send(json.dumps(call))
                try:
                    async with asyncio.timeout(10):
                        while True:
                            answer = json.loads(await ws.recv())
                            if answer.get("id") == str(number):
                                break
                except TimeoutError:
                    self.failures["bridge timeout"] += 1
                    continue
                if answer.get("result") is True:
                    self.latencies["bridge"].append(time.perf_counter() - started)
                else:
                    self.failures[f"bridge {str(answer.get('values'))[:40]}"] += 1


class Flooder:
    """Heavy queries, held-open streams and many bridge connections from 127.0.0.2, until ``stop``."""

    def __init__(self, http: int, bridge: int) -> None:
        self.http, self.bridge = http, bridge
        self.stopping = threading.Event()
        self.outcomes: Counter[str] = Counter()
        self.lock = threading.Lock()
        self.threads: list[threading.Thread] = []

    def count(self, what: str) -> None:
        with self.lock:
            self.outcomes[what] += 1

    def start(self) -> None:
        self.threads = [threading.Thread(target=self._heavy) for _ in range(4)]
        self.threads += [threading.Thread(target=self._stream) for _ in range(32)]
        self.threads.append(threading.Thread(target=lambda: asyncio.run(self._connections())))
        for thread in self.threads:
            thread.start()

    def stop(self) -> None:
        self.stopping.set()
        for thread in self.threads:
            thread.join(40)

    def _client(self, timeout: float) -> httpx.Client:
        return httpx.Client(transport=httpx.HTTPTransport(local_address=FLOODER), timeout=timeout)

    def _heavy(self) -> None:
        with self._client(60.0) as client:
            while not self.stopping.is_set():
                try:
                    response = client.get(f"http://127.0.0.1:{self.http}/sparql", params={"query": HEAVY})
                    self.count(f"heavy query: {response.status_code} {response.json().get('error', 'ok')}")
                    if response.status_code == 503 and response.json().get("error") == "busy":
                        self.stopping.wait(0.05)
                except httpx.HTTPError as error:
                    self.count(f"heavy query: {type(error).__name__}")

    def _stream(self) -> None:
        with self._client(5.0) as client:
            while not self.stopping.is_set():
                try:
                    with client.stream("GET", f"http://127.0.0.1:{self.http}/tasks/events") as stream:
                        self.count(f"stream: {stream.status_code}")
                        if stream.status_code != 200:
                            self.stopping.wait(0.5)
                            continue
                        for _ in stream.iter_lines():  # held open, reading heartbeats
                            if self.stopping.is_set():
                                break
                except httpx.HTTPError as error:
                    self.count(f"stream: {type(error).__name__}")

    async def _connections(self) -> None:
        async def one(index: int) -> None:
            try:
                async with connect(
                    f"ws://127.0.0.1:{self.bridge}", open_timeout=10, local_addr=(FLOODER, 0), close_timeout=2
                ) as ws:
                    await ws.send(json.dumps({"op": "subscribe", "topic": "/cbrs/events"}))
                    self.count("bridge connection: open")
                    number = 0
                    while not self.stopping.is_set():
                        if index < 8:
                            number += 1
                            args = {"query": HEAVY}
                            await ws.send(
                                json.dumps(
                                    {"op": "call_service", "id": str(number), "service": "/cbrs/query", "args": args}
                                )
                            )
                            reply = json.loads(await asyncio.wait_for(ws.recv(), 60))
                            self.count(f"bridge heavy: {str(reply.get('values'))[:24]}")
                        else:
                            with contextlib.suppress(TimeoutError):
                                await asyncio.wait_for(ws.recv(), 1.0)
            except Exception as error:  # refused (1013) or closed: counted, not raised
                self.count(f"bridge connection: {type(error).__name__}")

        await asyncio.gather(*(one(index) for index in range(200)))


def summary(victim: Victim) -> dict[str, Any]:
    found: dict[str, Any] = {}
    for surface, latencies in victim.latencies.items():
        failed = sum(n for key, n in victim.failures.items() if key.startswith(surface))
        ordered = sorted(latencies) or [float("nan")]
        found[surface] = {
            "answered": len(latencies),
            "failed": failed,
            "median_ms": statistics.median(ordered) * 1000,
            "p95_ms": ordered[int(0.95 * (len(ordered) - 1))] * 1000,
        }
    return found


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=20.0)
    parser.add_argument("--anchor-seconds", type=float, default=5.0)
    parser.add_argument("--timeout", type=float, default=5.0, help="the server's query_timeout")
    args = parser.parse_args()
    print(f"machine: {platform.platform()}, {os.cpu_count()} cores, python {platform.python_version()}")
    print(
        f"inputs: cbrs serve on a fresh seeded store on disk, query_timeout {args.timeout:g} s, other limits default; "
        f"victim {VICTIM} alone {args.anchor_seconds:g} s, then {args.seconds:g} s under a flood from {FLOODER}: "
        "4 heavy-query loops, 32 event streams, 200 bridge connections (8 sending the heavy query)"
    )
    with tempfile.TemporaryDirectory(prefix="cbrs-flood-") as folder:
        child, http, bridge = start_server(Path(folder), args.timeout)
        try:
            alone = Victim(http, bridge)
            alone.run(args.anchor_seconds)
            flooder = Flooder(http, bridge)
            flooder.start()
            time.sleep(1.0)  # the flood is on before the victim measures
            flooded = Victim(http, bridge)
            flooded.run(args.seconds)
            flooder.stop()
        finally:
            child.send_signal(signal.SIGINT)
            try:
                child.wait(30)
            except subprocess.TimeoutExpired:
                child.kill()
    before, during = summary(alone), summary(flooded)
    print(f"\n{'surface':8} {'phase':7} {'answered':>9} {'failed':>7} {'median ms':>10} {'p95 ms':>8} {'/s':>7}")
    for surface in ("http", "bridge"):
        for phase, figures, seconds in (("alone", before, args.anchor_seconds), ("flood", during, args.seconds)):
            f = figures[surface]
            rate = f["answered"] / seconds
            figures_text = f"{f['answered']:9d} {f['failed']:7d} {f['median_ms']:10.1f} {f['p95_ms']:8.1f} {rate:7.1f}"
            print(f"{surface:8} {phase:7} {figures_text}")
        ratio = during[surface]["median_ms"] / before[surface]["median_ms"]
        print(f"{surface:8} median under flood / alone: {ratio:.1f}x")
    if flooded.failures:
        print("victim failures under flood: " + ", ".join(f"{k} x{n}" for k, n in flooded.failures.most_common()))
    print("\nwhat the flood got:")
    for what, count in sorted(flooder.outcomes.items()):
        print(f"  {what}: {count}")


if __name__ == "__main__":
    main()
