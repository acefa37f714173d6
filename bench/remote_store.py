"""Benchmark: the same knowledge-base work on the embedded store and on an Oxigraph server over HTTP.

Run: python bench/remote_store.py [--repeat N] [--on-disk] [--url URL]. Without --url it starts
``oxigraph serve --union-default-graph`` (from the oxigraph package beside this interpreter) on a free
loopback port, in memory or (--on-disk) in a temporary directory, and stops it at the end; with --url
it uses that server and DROPs ALL its data first. Prints the machine, the inputs and the figures.
"""

from __future__ import annotations

import argparse
import os
import platform
import shutil
import socket
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path

import httpx
import pyoxigraph
from timing import samples_ms

from cbrs.kb import KnowledgeBase
from cbrs.kb.resources import bundled_files

LOCATE = "svc:LocateMobileRobot_CeilingCamera01"
CAMERA3 = """@prefix cbrs: <https://w3id.org/cbrs/core#> . @prefix home: <https://w3id.org/cbrs/home#> .
<https://w3id.org/cbrs/service#Bench> a cbrs:DynamicPerceptionComponent ;
    cbrs:deviceName "BenchCamera" ; cbrs:serviceName "LocateMobileRobot" ;
    cbrs:hasOWLSModel [ cbrs:hasInput [ cbrs:parameterType home:MarkerColour ] ;
                        cbrs:hasOutput [ cbrs:parameterType home:RobotLocation ] ] .
"""


def timed(action: Callable[[], object], repeat: int) -> list[float]:
    return sorted(samples_ms(action, repeat))


@contextmanager
def oxigraph_server(on_disk: bool) -> Iterator[tuple[str, str]]:
    """A fresh ``oxigraph serve`` (its URL and version), stopped on exit."""
    binary = Path(sys.executable).parent / "oxigraph"
    command_name = str(binary) if binary.is_file() else shutil.which("oxigraph")
    if command_name is None:
        raise SystemExit("no oxigraph binary: pip install oxigraph (or the test extra), or pass --url")
    version = subprocess.run([command_name, "--version"], capture_output=True, text=True).stdout.strip()
    with tempfile.TemporaryDirectory() as directory, socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
        probe.close()
        command = [command_name, "serve", "--bind", f"127.0.0.1:{port}", "--union-default-graph"]
        if on_disk:
            command += ["--location", str(Path(directory) / "data")]
        process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        url = f"http://127.0.0.1:{port}"
        try:
            deadline = time.monotonic() + 20
            while time.monotonic() < deadline:
                try:
                    httpx.get(url + "/", timeout=1.0)
                    break
                except httpx.TransportError:
                    time.sleep(0.05)
            yield url, version
        finally:
            process.terminate()
            process.wait(timeout=10)


def measure(location: str, repeat: int, reset: Callable[[], None]) -> dict[str, list[float]]:
    """Figures for one location: open and seed, open a seeded store, reads, a query, a write."""
    figures: dict[str, list[float]] = {}

    def open_and_seed() -> None:
        reset()
        KnowledgeBase.open(location).close()

    figures["open + seed an empty store"] = timed(open_and_seed, max(3, repeat // 10))
    if location != ":memory:":  # every open of :memory: is a new, empty store
        figures["open a seeded store"] = timed(lambda: KnowledgeBase.open(location).close(), repeat)
    kb = KnowledgeBase.open(location)

    def requirements() -> object:
        kb._reader.clear_cache()
        return kb.requirements()

    figures["requirements() (cold)"] = timed(requirements, max(3, repeat // 5))
    figures["advertisements() (cold)"] = timed(
        lambda: (kb._reader.clear_cache(), kb.advertisements()), max(3, repeat // 10)
    )
    figures["query advertisements (kind bound)"] = timed(
        lambda: kb.select("advertisements", {"kind": "cbrs:DynamicPerceptionComponent"}), repeat
    )
    figures["query description (bound)"] = timed(lambda: kb.select("description", {"description": LOCATE}), repeat)
    figures["dump (sorted N-Quads)"] = timed(kb.store.dump, max(3, repeat // 10))
    figures["register + deregister"] = timed(
        lambda: (kb.registry.register(CAMERA3), kb.registry.deregister("https://w3id.org/cbrs/service#Bench")),
        max(3, repeat // 5),
    )
    kb.close()
    return figures


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeat", type=int, default=30, help="runs per measured operation")
    parser.add_argument("--on-disk", action="store_true", help="start the server with --location in a temp dir")
    parser.add_argument("--url", help="use this Oxigraph server (started with --union-default-graph); erased first")
    args = parser.parse_args()

    print(
        f"machine: {platform.machine()} {platform.system()} {platform.release()}, {os.cpu_count()} cores, "
        f"python {platform.python_version()}, pyoxigraph {pyoxigraph.__version__}, httpx {httpx.__version__}"
    )
    with tempfile.TemporaryDirectory() as directory:
        embedded = str(Path(directory) / "store") if args.on_disk else ":memory:"
        if args.url:
            run(args.url, "given", embedded, args.repeat)
        else:
            with oxigraph_server(args.on_disk) as (url, version):
                run(url, f"{version}, {'on disk' if args.on_disk else 'in memory'}, loopback", embedded, args.repeat)


def run(url: str, server: str, location: str, repeat: int) -> None:
    client = httpx.Client()

    def erase() -> None:
        client.post(url + "/update", content=b"DROP ALL", headers={"Content-Type": "application/sparql-update"})

    def remove() -> None:
        shutil.rmtree(location, ignore_errors=True)

    seeded = KnowledgeBase.open(":memory:")
    print(
        f"inputs: the bundled files ({', '.join(f.path.name for f in bundled_files())}): {seeded.store.count()} quads, "
        f"{len(seeded.advertisements())} advertisements, {len(seeded.requirements())} requirements; repeat {repeat}"
    )
    print(f"embedded store: {location}; server: {url} ({server})")
    embedded = measure(location, repeat, remove)
    remote = measure(url, repeat, erase)
    ask = timed(
        lambda: client.post(url + "/query", content=b"ASK {}", headers={"Content-Type": "application/sparql-query"}),
        repeat,
    )
    print(f"\n{'operation':<36} {'embedded p50':>13} {'remote p50':>11} {'remote p95':>11} {'ratio':>7}  (ms)")
    for name, far in remote.items():
        p95 = far[min(len(far) - 1, int(len(far) * 0.95))]
        median = statistics.median(far)
        if name not in embedded:
            print(f"{name:<36} {'-':>13} {median:>11.2f} {p95:>11.2f}")
            continue
        near = statistics.median(embedded[name])
        print(f"{name:<36} {near:>13.2f} {median:>11.2f} {p95:>11.2f} {median / near:>7.1f}")
    print(f"{'one HTTP round trip (ASK {})':<36} {'':>13} {statistics.median(ask):>11.2f}")
    client.close()


if __name__ == "__main__":
    main()
