"""Benchmark: the bridge's publish -> subscriber throughput beside a minimal websockets relay (issue 18).

Run: python bench/rosbridge_relay.py [--messages M] [--publishers 1,4] [--size BYTES] [--rounds R] [--quick]
     [--json FILE]

Two servers, each in a child process of its own, on the same loopback and the same websockets library
(permessage-deflate off on both: each accepts no extension, ``compression=None``, so none is
negotiated; the bench checks that on every connection):

- cbrs: a default ``Bridge`` (what ``cbrs serve`` runs), publish relayed to a pass-through subscriber;
- the anchor: the least a rosbridge relay has to do, written here. It reads each text frame's JSON for
  ``op`` and ``topic``, keeps the subscribers of each topic, and sends each ``publish`` on to them in the
  protocol's form (the message encoded again), awaiting each send as websockets' flow control asks.
  No checks, no queues, no throttling, no statuses.

The clients are websockets sync clients in this process (as in bench/rosbridge.py): P publishers send M
messages in all, as fast as they can, to one subscriber; the rate is from the first send to the last
receive. Both servers get the same clients, payload and count. The machine is shared, so the bench
pairs its measurements: in each of R rounds the two servers are measured back to back (which goes
first alternates from round to round and row to row), and the round's ratio is cbrs's rate over the
relay's. A measurement is short (20,000 messages by default, about a second), so the two of a pair
see much the same machine, and there are many rounds (11) for the median. A row's ratio is the median
of its R round ratios, printed with their range; no round is left out (one in which either server
lost messages counts as ratio 0, against cbrs). Beside the rate, each server process's CPU time per
message (from /proc's per-thread schedstat), as medians and the median of the rounds' ratios: other
work disturbs it less than the rate, though not entirely (a server kept waiting finds fewer frames per
wake-up). And this process's CPU per message (the clients'), which shows whether the clients or a
server set the pace. One short
warm-up round per server and count comes first and is not counted. Prints the machine, the load
average (at the start, before each pair, at the end), the inputs and every round; ``--json FILE``
writes the rows as records ``{row, value, anchor, ratio, unit, goal, met}`` (value and anchor the
median rates, ratio the median round ratio) with ``spread``, ``rounds``, ``cpu_us_per_message`` and
``load_average`` besides.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import multiprocessing
import os
import platform
import statistics
import threading
import time
from collections.abc import Callable
from contextlib import ExitStack
from dataclasses import dataclass, field
from multiprocessing.synchronize import Event
from pathlib import Path
from typing import Any

from websockets.asyncio.server import ServerConnection
from websockets.asyncio.server import serve as ws_serve
from websockets.exceptions import ConnectionClosed
from websockets.sync.client import ClientConnection, connect

TIMEOUT = 10.0
GOAL = ">= 0.9x"
GOAL_RATIO = 0.9


def serve_cbrs(ports: multiprocessing.Queue[int], stop: Event) -> None:
    """Child process: a default bridge until told to stop."""
    from cbrs.rosbridge import Bridge

    running = Bridge().start(port=0)
    ports.put(running.port)
    stop.wait()
    running.stop()


async def _relay(ports: multiprocessing.Queue[int], stop: Event) -> None:
    subscribers: dict[str, set[ServerConnection]] = {}

    async def connection(websocket: ServerConnection) -> None:
        mine: set[str] = set()
        try:
            async for frame in websocket:
                message = json.loads(frame)
                op, topic = message.get("op"), message.get("topic")
                if op == "subscribe":
                    subscribers.setdefault(topic, set()).add(websocket)
                    mine.add(topic)
                elif op == "publish":
                    text = json.dumps({"op": "publish", "topic": topic, "msg": message["msg"]})
                    for subscriber in list(subscribers.get(topic, ())):
                        try:
                            await subscriber.send(text)
                        except ConnectionClosed:
                            subscribers[topic].discard(subscriber)
                elif op == "call_service":  # only the clients' sync: answered at once
                    reply = {"op": "service_response", "service": message.get("service"), "values": {}, "result": True}
                    await websocket.send(json.dumps({**reply, "id": message.get("id")}))
        except ConnectionClosed:
            pass
        finally:
            for topic in mine:
                subscribers[topic].discard(websocket)

    async with ws_serve(connection, "127.0.0.1", 0, max_size=16 << 20, compression=None) as server:
        ports.put(int(server.sockets[0].getsockname()[1]))
        while not stop.is_set():
            await asyncio.sleep(0.1)


def serve_relay(ports: multiprocessing.Queue[int], stop: Event) -> None:
    """Child process: the minimal relay until told to stop."""
    asyncio.run(_relay(ports, stop))


def send(ws: ClientConnection, **message: Any) -> None:
    ws.send(json.dumps(message))


def sync(ws: ClientConnection) -> None:
    """Return once the server has handled everything ``ws`` sent before."""
    send(ws, op="call_service", service="/rosapi/get_time", id="sync")
    while json.loads(ws.recv(timeout=TIMEOUT)).get("id") != "sync":
        pass


def rate(url: str, messages: int, publishers: int, payload: str) -> tuple[float, int]:
    """Messages per second from ``publishers`` connections to one subscriber, and how many arrived."""
    each = messages // publishers
    with ExitStack() as stack:
        listener = stack.enter_context(connect(url, max_size=None))
        talkers = [stack.enter_context(connect(url, max_size=None)) for _ in range(publishers)]
        for ws in (listener, *talkers):
            if ws.protocol.extensions:  # a compressed server would do other work than the relay
                raise RuntimeError(f"{url} negotiated {ws.protocol.extensions}: the bench compares uncompressed")
        send(listener, op="subscribe", topic="/bench/rate", type="bench/Blob")
        sync(listener)
        for ws in talkers:
            send(ws, op="advertise", topic="/bench/rate", type="bench/Blob")
            sync(ws)
        go = threading.Barrier(publishers + 1)

        def flood(ws: ClientConnection, k: int) -> None:
            go.wait()
            for n in range(each):
                send(ws, op="publish", topic="/bench/rate", msg={"k": k, "n": n, "data": payload})

        threads = [threading.Thread(target=flood, args=(ws, k)) for k, ws in enumerate(talkers)]
        for thread in threads:
            thread.start()
        go.wait()
        start = time.perf_counter()
        received, last = 0, start
        try:
            while received < each * publishers:
                listener.recv(timeout=2.0)
                received += 1
                last = time.perf_counter()
        except TimeoutError:  # some were dropped
            pass
        for thread in threads:
            thread.join(TIMEOUT)
        return received / (last - start), received


class Server:
    """A server in a child process of its own, started and stopped with the ``with`` block."""

    def __init__(self, target: Callable[[multiprocessing.Queue[int], Event], None]) -> None:
        context = multiprocessing.get_context("spawn")
        self._ports: multiprocessing.Queue[int] = context.Queue()
        self._stop = context.Event()
        self._child = context.Process(target=target, args=(self._ports, self._stop), daemon=True)
        self.url = ""

    def __enter__(self) -> Server:
        self._child.start()
        self.url = f"ws://127.0.0.1:{self._ports.get(timeout=30)}"
        return self

    def __exit__(self, *exc: object) -> None:
        self._stop.set()
        self._child.join(TIMEOUT)

    def cpu(self) -> float:
        """CPU seconds the server process's threads have run so far: the nanosecond counters of
        /proc/PID/task/*/schedstat (Linux), finer than /proc/PID/stat's clock ticks (10 ms, which is
        3% of a 10,000-message round)."""
        tasks = Path(f"/proc/{self._child.pid}/task")
        total = 0
        for task in tasks.iterdir():
            try:
                total += int((task / "schedstat").read_text().split()[0])
            except (FileNotFoundError, ProcessLookupError):  # a thread that ended meanwhile
                continue
        return total / 1e9


@dataclass
class Pair:
    """One round of one publisher count: both servers measured back to back, in the order given."""

    order: tuple[str, str]
    load: float  # 1-minute load average just before the pair
    rate: dict[str, float] = field(default_factory=dict)  # msg/s; 0 if the round lost messages
    cpu: dict[str, float] = field(default_factory=dict)  # server CPU us per received message
    client: dict[str, float] = field(default_factory=dict)  # this process's CPU us per message

    def ratio(self, what: str) -> float:
        figures = self.rate if what == "rate" else self.cpu
        return figures["cbrs"] / figures["relay"] if figures["relay"] else 0.0


def one(server: Server, messages: int, count: int, payload: str) -> tuple[float, float, float, int]:
    """One server's round: its rate (0 if messages were lost), server and client CPU us per message."""
    before, mine = server.cpu(), time.process_time()
    measured, received = rate(server.url, messages, count, payload)
    per_message = (server.cpu() - before) / max(received, 1) * 1e6
    client = (time.process_time() - mine) / max(received, 1) * 1e6
    sent = messages // count * count
    return (measured if received == sent else 0.0), per_message, client, received


def measure(args: argparse.Namespace, counts: list[int]) -> dict[int, list[Pair]]:
    """Every round's pair of measurements, by publisher count. Before the rounds, one short warm-up
    round per server and count (both servers alike, not counted: the first messages a fresh process
    relays pay for imports and caches)."""
    payload = "x" * args.size
    pairs: dict[int, list[Pair]] = {count: [] for count in counts}
    with Server(serve_cbrs) as cbrs, Server(serve_relay) as relay:
        servers = {"cbrs": cbrs, "relay": relay}
        for count in counts:
            for server in servers.values():
                rate(server.url, min(args.messages, 2000), count, payload)
        for n in range(args.rounds):
            for k, count in enumerate(counts):
                order = ("cbrs", "relay") if (n + k) % 2 == 0 else ("relay", "cbrs")  # who goes first alternates
                pair = Pair(order, os.getloadavg()[0])
                for name in order:
                    measured, cpu, client, received = one(servers[name], args.messages, count, payload)
                    pair.rate[name], pair.cpu[name], pair.client[name] = measured, cpu, client
                    print(
                        f"  round {n + 1}: {name:<5} {count:>2} publisher(s) {measured:>9,.0f} msg/s "
                        f"{received:>6} received, server CPU {cpu:5.1f} us/msg, client CPU {client:5.1f} us/msg "
                        f"(load {pair.load:.2f})"
                    )
                pairs[count].append(pair)
    return pairs


def summary(count: int, pairs: list[Pair]) -> dict[str, Any]:
    """The row of one publisher count: median rates and CPU, the median of the rounds' ratios and their
    range (every round counts: a round in which either server lost messages has ratio 0)."""
    rates, cpus = [p.ratio("rate") for p in pairs], [p.ratio("cpu") for p in pairs]
    ratio = statistics.median(rates)
    return {
        "row": f"publish -> subscriber, {count} publisher(s)",
        "value": round(statistics.median([p.rate["cbrs"] for p in pairs])),
        "anchor": round(statistics.median([p.rate["relay"] for p in pairs])),
        "ratio": round(ratio, 3),
        "unit": "msg/s",
        "goal": GOAL,
        "met": ratio >= GOAL_RATIO,
        "spread": [round(min(rates), 3), round(max(rates), 3)],
        "rounds": len(pairs),
        "cpu_us_per_message": {
            "cbrs": round(statistics.median([p.cpu["cbrs"] for p in pairs]), 1),
            "relay": round(statistics.median([p.cpu["relay"] for p in pairs]), 1),
            "ratio": round(statistics.median(cpus), 3),
            "spread": [round(min(cpus), 3), round(max(cpus), 3)],
        },
        "load_average": [round(min(p.load for p in pairs), 2), round(max(p.load for p in pairs), 2)],
    }


def report(records: list[dict[str, Any]]) -> None:
    print(
        f"\n  {'row (median of rounds)':<38} {'cbrs':>8} {'relay':>8} {'ratio':>6} {'range':>12}"
        f"  {'goal':<8} {'':<7} | {'CPU us/msg: cbrs':>16} {'relay':>6} {'ratio':>6} {'range':>12}"
    )
    for r in records:
        cpu = r["cpu_us_per_message"]
        spread, cpu_spread = "{:.2f}-{:.2f}x".format(*r["spread"]), "{:.2f}-{:.2f}x".format(*cpu["spread"])
        print(
            f"  {r['row']:<38} {r['value']:>8,} {r['anchor']:>8,} {r['ratio']:>5.2f}x {spread:>12}  {GOAL:<8} "
            f"{'met' if r['met'] else 'NOT met':<7} | {cpu['cbrs']:>16.1f} {cpu['relay']:>6.1f} "
            f"{cpu['ratio']:>5.2f}x {cpu_spread:>12}"
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--messages", type=int, default=20000, help="messages per measurement")
    parser.add_argument("--publishers", default="1,4", help="publisher counts, comma-separated")
    parser.add_argument("--size", type=int, default=100, help="bytes of payload per message")
    parser.add_argument("--rounds", type=int, default=11, help="rounds (pairs of measurements) per publisher count")
    parser.add_argument("--quick", action="store_true", help="10000 messages and 5 rounds (a rough look)")
    parser.add_argument("--json", type=Path, help="write the rows to FILE as a JSON list of records")
    args = parser.parse_args()
    if args.quick:
        args.messages, args.rounds = 10000, 5
    counts = [int(c) for c in args.publishers.split(",")]
    print(f"machine: {platform.platform()}, {os.cpu_count()} cores, python {platform.python_version()}")
    print("load average at the start: {:.2f} {:.2f} {:.2f}".format(*os.getloadavg()))
    print(
        f"inputs: {args.messages} messages of {args.size}-byte payload per measurement, publishers {counts} -> 1 "
        f"subscriber, {args.rounds} rounds; in each round the two servers back to back, the first "
        "alternating; servers in child processes, websockets sync clients here, loopback"
    )
    pairs = measure(args, counts)
    print("load average at the end: {:.2f} {:.2f} {:.2f}".format(*os.getloadavg()))
    records = [summary(count, pairs[count]) for count in counts]
    report(records)
    if args.json is not None:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps(records, indent=2) + "\n")
        print(f"\nwritten to {args.json}")


if __name__ == "__main__":
    main()
