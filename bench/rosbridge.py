"""Benchmark: the rosbridge server's round-trip latency and message rate over loopback websockets.

Run: python bench/rosbridge.py [--samples N] [--messages M] [--publishers 1,4,16] [--size BYTES].
Prints the machine (with its load average, at the start and the end), the inputs and the figures.
The server (a default Bridge) runs in a child process, so it has an interpreter lock of its own; the
clients are websockets sync clients in this process.
Latency is measured one message at a time: publish -> the subscriber has it; call_service ->
service_response, for a trivial server service (run on a worker thread), for rosapi (answered on the
event loop) and for a service a client provides (relayed both ways). Rate: M messages sent as fast as
the publishers can, to one pass-through subscriber, from the first send to the last receive.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import os
import platform
import statistics
import threading
import time
from collections.abc import Callable
from contextlib import ExitStack
from multiprocessing.synchronize import Event
from typing import Any

from websockets.sync.client import ClientConnection, connect

from cbrs.rosbridge import Bridge

TIMEOUT = 10.0


def serve(ports: multiprocessing.Queue[int], stop: Event) -> None:
    """The child process: a default bridge with one trivial service, until told to stop."""
    bridge = Bridge()
    bridge.add_service("/bench/echo", "bench/Echo", lambda args: args)
    running = bridge.start(port=0)
    ports.put(running.port)
    stop.wait()
    running.stop()


def send(ws: ClientConnection, **message: Any) -> None:
    ws.send(json.dumps(message))


def recv(ws: ClientConnection) -> dict[str, Any]:
    message: dict[str, Any] = json.loads(ws.recv(timeout=TIMEOUT))
    return message


def sync(ws: ClientConnection) -> None:
    """Return once the server has handled everything ``ws`` sent before."""
    send(ws, op="call_service", service="/rosapi/get_time", id="sync")
    while recv(ws).get("id") != "sync":
        pass


def summary(samples: list[float]) -> str:
    samples = sorted(samples)
    p95 = samples[min(len(samples) - 1, int(0.95 * len(samples)))]
    return f"{statistics.median(samples) * 1000:>10.3f} {p95 * 1000:>8.3f}"


def latency(samples: int, step: Callable[[int], None]) -> list[float]:
    for n in range(min(50, samples)):  # warm up
        step(n)
    times = []
    for n in range(samples):
        start = time.perf_counter()
        step(n)
        times.append(time.perf_counter() - start)
    return times


def measure_latency(url: str, samples: int, payload: str) -> None:
    with ExitStack() as stack:
        talker, listener, provider = (stack.enter_context(connect(url, max_size=None)) for _ in range(3))
        send(listener, op="subscribe", topic="/bench/latency", type="bench/Blob")
        send(talker, op="advertise", topic="/bench/latency", type="bench/Blob")
        send(provider, op="advertise_service", service="/bench/relay", type="bench/Echo")
        for ws in (listener, talker, provider):
            sync(ws)

        def publish(n: int) -> None:
            send(talker, op="publish", topic="/bench/latency", msg={"n": n, "data": payload})
            recv(listener)

        def call(service: str) -> Callable[[int], None]:
            def step(n: int) -> None:
                send(talker, op="call_service", service=service, args={"n": n}, id=n)
                recv(talker)

            return step

        def relayed(n: int) -> None:
            send(talker, op="call_service", service="/bench/relay", args={"n": n}, id=n)
            request = recv(provider)
            send(provider, op="service_response", service="/bench/relay", id=request["id"], values={}, result=True)
            recv(talker)

        print(f"\n{'round trip':<46} {'median ms':>10} {'p95 ms':>8}")
        print(f"{'publish -> subscriber has it':<46} {summary(latency(samples, publish))}")
        print(f"{'call_service, server service (worker thread)':<46} {summary(latency(samples, call('/bench/echo')))}")
        print(
            f"{'call_service, rosapi/get_time (event loop)':<46} {summary(latency(samples, call('/rosapi/get_time')))}"
        )
        print(f"{'call_service, provided by another client':<46} {summary(latency(samples, relayed))}")


def measure_rate(url: str, messages: int, publishers: int, payload: str) -> tuple[float, int]:
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
        except TimeoutError:  # some were dropped (a subscriber falling far behind loses the oldest)
            pass
        for thread in threads:
            thread.join(TIMEOUT)
        return received / (last - start), received


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=2000, help="round trips per latency figure")
    parser.add_argument("--messages", type=int, default=20000, help="messages per rate figure")
    parser.add_argument("--publishers", default="1,4,16", help="publisher counts for the rate figures")
    parser.add_argument("--size", type=int, default=100, help="bytes of payload per message")
    args = parser.parse_args()
    print(
        f"machine: {platform.platform()}, {os.cpu_count()} cores, python {platform.python_version()}, "
        f"load average {os.getloadavg()[0]:.2f}"
    )
    print(
        f"inputs: default Bridge in a child process, loopback, websockets sync clients; {args.samples} round trips "
        f"per latency, {args.messages} messages per rate, {args.size}-byte payload"
    )
    context = multiprocessing.get_context("spawn")
    ports: multiprocessing.Queue[int] = context.Queue()
    stop = context.Event()
    child = context.Process(target=serve, args=(ports, stop), daemon=True)
    child.start()
    try:
        url = f"ws://127.0.0.1:{ports.get(timeout=30)}"
        payload = "x" * args.size
        measure_latency(url, args.samples, payload)
        print(f"\n{'publishers -> 1 subscriber':<28} {'messages/s':>11} {'received':>15}")
        for count in (int(c) for c in args.publishers.split(",")):
            rate, received = measure_rate(url, args.messages, count, payload)
            sent = args.messages // count * count
            print(f"{count:<28} {rate:>11,.0f} {received:>7}/{sent:<7}")
    finally:
        stop.set()
        child.join(TIMEOUT)
    print(f"\nload average at the end: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
