"""Benchmark: the bridge's publish -> subscriber throughput beside a minimal websockets relay (issue 18).

Run: python bench/rosbridge_relay.py [--messages M] [--publishers 1,4] [--size BYTES] [--rounds R] [--json FILE]

Two servers, each in a child process of its own, on the same loopback and the same websockets library:

- cbrs: a default ``Bridge`` (what ``cbrs serve`` runs), publish relayed to a pass-through subscriber;
- the anchor: the least a rosbridge relay has to do, written here. It reads each text frame's JSON for
  ``op`` and ``topic``, keeps the subscribers of each topic, and sends each ``publish`` on to them in the
  protocol's form (the message encoded again), awaiting each send as websockets' flow control asks.
  No checks, no queues, no throttling, no statuses.

The clients are websockets sync clients in this process (as in bench/rosbridge.py): P publishers send M
messages in all, as fast as they can, to one subscriber; the rate is from the first send to the last
receive. Beside it, the server process's CPU time per message (user + system, from /proc), which other
work on the machine disturbs far less than the rate. The two servers are measured in turns, R rounds
each, in one run on one machine; the best round of each is its rate (other work only ever slows a round
down; the median round is printed too), and the median round its CPU per message. Prints the machine
(with its load average), the inputs, both figures and the ratio of each row; ``--json FILE`` writes the
rate rows as records ``{row, value, anchor, ratio, unit, goal, met}``.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import multiprocessing
import os
import platform
import threading
import time
from collections.abc import Callable
from contextlib import ExitStack
from multiprocessing.synchronize import Event
from pathlib import Path
from typing import Any

from websockets.asyncio.server import ServerConnection
from websockets.asyncio.server import serve as ws_serve
from websockets.exceptions import ConnectionClosed
from websockets.sync.client import ClientConnection, connect

TIMEOUT = 10.0
GOAL = ">= 0.9x"
Key = tuple[str, int]  # (server, publishers)


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
        """CPU seconds (user + system) the server process has used so far (Linux /proc)."""
        fields = Path(f"/proc/{self._child.pid}/stat").read_text().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def median(values: list[float]) -> float:
    ordered = sorted(values)
    return ordered[len(ordered) // 2]


def measure(args: argparse.Namespace, counts: list[int]) -> tuple[dict[Key, list[float]], dict[Key, list[float]]]:
    """Each server's rate and CPU per message in every round (a round that lost messages has rate 0),
    by (server, publishers)."""
    payload = "x" * args.size
    rates: dict[Key, list[float]] = {}
    cpu: dict[Key, list[float]] = {}
    with Server(serve_cbrs) as cbrs, Server(serve_relay) as relay:
        for n in range(args.rounds):
            for count in counts:
                for name, server in (("cbrs", cbrs), ("relay", relay)):
                    before = server.cpu()
                    measured, received = rate(server.url, args.messages, count, payload)
                    per_message = (server.cpu() - before) / max(received, 1) * 1e6
                    cpu.setdefault((name, count), []).append(per_message)
                    sent = args.messages // count * count
                    print(
                        f"  round {n + 1}: {name:<5} {count:>2} publisher(s) {measured:>9,.0f} msg/s "
                        f"{received}/{sent}, server CPU {per_message:5.1f} us/msg"
                    )
                    rates.setdefault((name, count), []).append(measured if received == sent else 0.0)
    return rates, cpu


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--messages", type=int, default=30000, help="messages per round")
    parser.add_argument("--publishers", default="1,4", help="publisher counts, comma-separated")
    parser.add_argument("--size", type=int, default=100, help="bytes of payload per message")
    parser.add_argument("--rounds", type=int, default=5, help="rounds per server and publisher count (best kept)")
    parser.add_argument("--json", type=Path, help="write the rows to FILE as a JSON list of records")
    args = parser.parse_args()
    counts = [int(c) for c in args.publishers.split(",")]
    print(
        f"machine: {platform.platform()}, {os.cpu_count()} cores, python {platform.python_version()}, "
        f"load average {os.getloadavg()[0]:.2f}"
    )
    print(
        f"inputs: {args.messages} messages of {args.size}-byte payload per round, publishers {counts} -> 1 "
        f"subscriber, {args.rounds} rounds per server in turns (best kept); servers in child processes, "
        "websockets sync clients here, loopback"
    )
    rates, cpu = measure(args, counts)
    records = []
    print(f"\n  {'row':<44} {'cbrs':>10} {'relay':>10} {'ratio':>7}  {'unit':<6} {'goal':<8}")
    for count in counts:
        value, anchor = max(rates[("cbrs", count)]), max(rates[("relay", count)])
        ratio = value / anchor if anchor else 0.0
        row = f"publish -> subscriber, {count} publisher(s)"
        met = ratio >= float(GOAL.split()[1].rstrip("x"))
        records.append(
            {"row": row, "value": round(value), "anchor": round(anchor), "ratio": round(ratio, 3), "unit": "msg/s",
             "goal": GOAL, "met": met}
        )  # fmt: skip
        verdict = "met" if met else "NOT met"
        print(f"  {row:<44} {value:>10,.0f} {anchor:>10,.0f} {ratio:>6.2f}x  msg/s  {GOAL:<8} {verdict}")
    print(f"\n  {'median round, publish -> subscriber':<44} {'cbrs':>10} {'relay':>10} {'ratio':>7}  unit")
    for count in counts:
        value, anchor = median(rates[("cbrs", count)]), median(rates[("relay", count)])
        ratio = value / anchor if anchor else 0.0
        print(f"  {f'{count} publisher(s)':<44} {value:>10,.0f} {anchor:>10,.0f} {ratio:>6.2f}x  msg/s")
    print(f"\n  {'server CPU per message (median of rounds)':<44} {'cbrs':>10} {'relay':>10} {'ratio':>7}  unit")
    for count in counts:
        value, anchor = median(cpu[("cbrs", count)]), median(cpu[("relay", count)])
        print(f"  {f'{count} publisher(s)':<44} {value:>10.1f} {anchor:>10.1f} {value / anchor:>6.2f}x  us/msg")
    if args.json is not None:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps(records, indent=2) + "\n")
        print(f"\nwritten to {args.json}")


if __name__ == "__main__":
    main()
