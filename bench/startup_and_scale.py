"""Benchmark: start-up, composition at scale, /cbrs/plan over the bridge and matchmaker memory (issue 18).

Run: python bench/startup_and_scale.py [--quick] [--repeat 5] [--chain 10000] [--classes 64000] [--ads 2000]
[--requirements 200] [--json FILE]

Each row is measured next to an anchor in the same run: a bare ``python -c pass`` and ``oxigraph serve``
for the process starts, the in-process composer for /cbrs/plan (the two called in turns; the first call
of each, which builds the composer, is shown apart), the memory before the requirements for the
matchmaker. Prints the machine, the inputs, the figures and the ratios; ``--json FILE`` writes
the rows of issue 18 as records ``{row, value, anchor, ratio, unit, goal, met}`` (bench/all_rows.py
merges them with the other benches').
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import shutil
import socket
import statistics
import subprocess
import sys
import tempfile
import time
import urllib.request
from pathlib import Path
from typing import Any

PYTHON = sys.executable
FETCH = "FetchMyPen"


def _median_seconds(argv: list[str], repeat: int) -> tuple[float, float]:
    """Median wall seconds of running ``argv``, and its median CPU seconds (user + system, all its
    threads): on a shared machine the wall time grows with the load, the CPU time much less."""
    samples, cpu = [], []
    for _ in range(repeat):
        used = resource.getrusage(resource.RUSAGE_CHILDREN)
        start = time.perf_counter()
        subprocess.run(argv, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        samples.append(time.perf_counter() - start)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu.append(after.ru_utime + after.ru_stime - used.ru_utime - used.ru_stime)
    return statistics.median(samples), statistics.median(cpu)


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


def _ready_seconds(argv: list[str], url: str) -> float:
    """From spawning ``argv`` to the first answer of ``url`` (a server's ready time)."""
    start = time.perf_counter()
    process = subprocess.Popen(argv, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        while True:
            try:
                urllib.request.urlopen(url, timeout=1).read()
                return time.perf_counter() - start
            except OSError:
                if process.poll() is not None:
                    raise RuntimeError(f"{argv[0]} exited with {process.returncode}") from None
                time.sleep(0.005)
    finally:
        process.terminate()
        process.wait()


def startup(repeat: int) -> tuple[dict[str, float], dict[str, float]]:
    """Wall seconds of each process start and server's ready time, and CPU seconds of the process starts."""
    cbrs = [PYTHON, "-m", "cbrs"]
    ask = "/query?query=ASK%7B%7D"
    with tempfile.TemporaryDirectory() as folder:
        store = Path(folder) / "store"
        subprocess.run([*cbrs, "--store", str(store), "init"], check=True, stdout=subprocess.DEVNULL)
        commands = {
            "python -c pass": [PYTHON, "-c", "pass"],
            "cbrs --help": [*cbrs, "--help"],
            # an in-memory store is seeded with the bundled ontologies at every start
            "cbrs query (:memory:)": [*cbrs, "--store", ":memory:", "query", "ASK {}"],
            "cbrs query (on-disk store)": [*cbrs, "--store", str(store), "query", "ASK {}"],
        }
        timed = {name: _median_seconds(argv, repeat) for name, argv in commands.items()}
        figures = {name: wall for name, (wall, _) in timed.items()}
        cpu = {name: used for name, (_, used) in timed.items()}
        serve: list[float] = []
        for _ in range(repeat):
            port = _free_port()
            argv = [*cbrs, "--store", str(store), "serve", "--port", str(port), "--bridge-port", "0"]
            serve.append(_ready_seconds(argv, f"http://127.0.0.1:{port}/sparql?query=ASK%7B%7D"))
        figures["cbrs serve ready (on-disk store)"] = statistics.median(serve)
        oxigraph = shutil.which("oxigraph") or str(Path(PYTHON).parent / "oxigraph")
        if Path(oxigraph).exists():
            anchor: list[float] = []
            for n in range(repeat):
                port = _free_port()
                argv = [oxigraph, "serve", "--location", str(Path(folder) / f"ox{n}"), "--bind", f"127.0.0.1:{port}"]
                anchor.append(_ready_seconds(argv, f"http://127.0.0.1:{port}{ask}"))
            figures["oxigraph serve ready"] = statistics.median(anchor)
    return figures, cpu


def composition(chain: int) -> dict[str, float]:
    from cbrs.actions.composer import ComposeConfig, Composer, PlanStatus
    from cbrs.actions.model import ActionLibrary
    from cbrs.kb import Advertisement, KnowledgeBase, Parameter, Requirement
    from cbrs.reasoner.taxonomy import ROOT, Link, TaxonomyIndex

    ns = "http://example.org/scale#"
    links = [Link(f"{ns}C{i}", ROOT, "is-a") for i in range(chain + 1)] + [Link(ns + "X", ROOT, "is-a")]
    pool = [
        Advertisement(
            iri=f"{ns}ad{i}",
            types=(),
            inputs=(Parameter(f"{ns}ad{i}in", "input", f"{ns}C{i}"),),
            outputs=(Parameter(f"{ns}ad{i}out", "output", f"{ns}C{i + 1}"),),
        )
        for i in range(chain)
    ]
    start = time.perf_counter()
    composer = Composer(
        KnowledgeBase.open(":memory:"),
        ComposeConfig(matched=False),
        index=TaxonomyIndex.from_links(links),
        actions=ActionLibrary(),
        advertisements=pool,
    )
    _ = composer.pool
    built = time.perf_counter() - start

    def compose(given: str) -> float:
        requirement = Requirement(
            iri=ns + "req",
            types=(),
            inputs=(Parameter(ns + "given", "input", given),),
            outputs=(Parameter(ns + "wanted", "output", f"{ns}C{chain}"),),
        )
        start = time.perf_counter()
        result = composer.compose(requirement)
        seconds = time.perf_counter() - start
        assert result.status is (PlanStatus.PLANNED if given != ns + "X" else PlanStatus.UNSOLVABLE)
        return seconds

    return {
        "pool build": built,
        f"unsolvable, explained down {chain} links": compose(ns + "X"),
        "planned, 5 steps at the chain's end": compose(f"{ns}C{chain - 5}"),
    }


def plan_over_bridge(repeat: int) -> dict[str, float]:
    from cbrs.actions.composer import Composer
    from cbrs.bridge_client import BridgeClient
    from cbrs.kb import KnowledgeBase
    from cbrs.server import ServeConfig, Server

    kb = KnowledgeBase.open(":memory:")
    start = time.perf_counter()
    composer = Composer(kb)
    composer.compose(FETCH)
    local_first = time.perf_counter() - start
    server = Server(kb, ServeConfig(port=0, bridge_port=0))
    server.start()
    local, remote = [], []
    try:
        with BridgeClient(f"ws://127.0.0.1:{server.bridge_port}") as client:
            start = time.perf_counter()
            client.call_sync("/cbrs/plan", {"task": FETCH})  # builds the server's composer
            remote_first = time.perf_counter() - start
            for _ in range(repeat * 4):  # in turns, so that both see the same load on a shared machine
                start = time.perf_counter()
                composer.compose(FETCH)
                local.append(time.perf_counter() - start)
                start = time.perf_counter()
                client.call_sync("/cbrs/plan", {"task": FETCH})
                remote.append(time.perf_counter() - start)
    finally:
        server.stop()
    return {
        "Composer.compose in-process": statistics.median(local),
        "/cbrs/plan over the bridge": statistics.median(remote),
        "first compose, new Composer": local_first,
        "first /cbrs/plan, new server": remote_first,
    }


def matchmaker_memory(classes: int, ads: int, requirements: int) -> dict[str, float]:
    from cbrs.kb import KnowledgeBase, Requirement
    from cbrs.reasoner import synthetic
    from cbrs.reasoner.matchmaker import Matchmaker

    def rss() -> float:
        return int(Path("/proc/self/statm").read_text().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20

    index, pool, wanted = synthetic.build(classes, ads, requirements + 1, seed=11)
    matchmaker = Matchmaker(KnowledgeBase.open(":memory:"), index=index, advertisements=pool).prepare()

    def rank(requirement: Requirement) -> None:  # the first candidate read, so that it is explained
        assert matchmaker.rank(requirement, explain=1).candidates[0].explained

    rank(wanted[0])
    before = rss()
    half = requirements // 2
    start = time.perf_counter()
    for requirement in wanted[1 : half + 1]:
        rank(requirement)
    middle = rss()
    for requirement in wanted[half + 1 :]:
        rank(requirement)
    after = rss()
    return {
        "RSS before the requirements, MB": before,
        f"RSS after {requirements} distinct requirements, MB": after,
        "MB per requirement, second half": (after - middle) / max(1, requirements - half),
        "ms per ranking": (time.perf_counter() - start) * 1000 / requirements,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--chain", type=int, default=10_000)
    parser.add_argument("--classes", type=int, default=64_000)
    parser.add_argument("--ads", type=int, default=2_000)
    parser.add_argument("--requirements", type=int, default=200)
    parser.add_argument("--quick", action="store_true", help="3 repeats, a 2,000-link chain, 8,000 classes")
    parser.add_argument("--json", type=Path, help="Also write the rows to FILE as a JSON list of records.")
    args = parser.parse_args()
    if args.quick:
        args.repeat, args.chain, args.classes, args.ads, args.requirements = 3, 2_000, 8_000, 500, 40
    load = os.getloadavg()[0]
    machine = f"{platform.platform()}, {os.cpu_count()} cores, python {platform.python_version()}"
    print(f"machine: {machine}, load average {load:.2f}")
    if os.environ.get("PYTHONDONTWRITEBYTECODE"):
        # every process start then compiles cbrs's sources again (about 0.1-0.2 s here): not what users see
        print("note: PYTHONDONTWRITEBYTECODE is set, so the process starts include compiling the sources")
    print(
        f"inputs: repeat {args.repeat}; chain pool of {args.chain} advertisements; matchmaker over "
        f"{args.classes} classes, {args.ads} advertisements, {args.requirements} distinct requirements"
    )
    record: dict[str, Any] = {"machine": platform.platform(), "cores": os.cpu_count(), "load": load}

    print("\nProcess start (median of repeat, seconds; CPU: user + system of the process):")
    figures, cpu = record["startup"], record["startup_cpu"] = startup(args.repeat)
    bare = figures["python -c pass"]
    for name, seconds in figures.items():
        anchor = figures.get("oxigraph serve ready") if "serve" in name else bare
        ratio = f"{seconds / anchor:6.1f}x {'oxigraph serve' if 'serve' in name else 'python -c pass'}"
        used = f"  CPU {cpu[name]:6.3f}" if name in cpu else ""
        print(f"  {name:<36} {seconds:7.3f}  {ratio if anchor else ''}{used}")

    print("\nComposition over a chain pool (seconds):")
    try:
        record["composition"] = composition(args.chain)
    except RecursionError as error:  # what the composer raised before issue 18
        record["composition"] = {"error": f"RecursionError: {error}"}
        print(f"  RecursionError: {error}")
    else:
        for name, seconds in record["composition"].items():
            print(f"  {name:<42} {seconds:7.3f}")

    print("\n/cbrs/plan FetchMyPen (median, ms):")
    plan = record["plan"] = plan_over_bridge(args.repeat)
    for name, seconds in plan.items():
        anchor = plan["first compose, new Composer" if name.startswith("first") else "Composer.compose in-process"]
        print(f"  {name:<36} {seconds * 1000:7.1f}  {seconds / anchor:5.2f}x in-process")

    print("\nMatchmaker memory:")
    record["memory"] = matchmaker_memory(args.classes, args.ads, args.requirements)
    for name, value in record["memory"].items():
        print(f"  {name:<42} {value:8.1f}")
    if args.json is not None:
        args.json.parent.mkdir(parents=True, exist_ok=True)
        args.json.write_text(json.dumps(records(record, args.requirements), indent=2) + "\n")
        print(f"\nwritten to {args.json}")


def records(record: dict[str, Any], requirements: int) -> list[dict[str, Any]]:
    """The figures as issue 18's rows: ``{row, value, anchor, ratio, unit, goal, met}``."""

    def row(name: str, value: float | None, anchor: float | None, unit: str, goal: str, met: bool | None = None):
        ratio = value / anchor if value is not None and anchor else None
        if met is None:  # an absolute goal: "<= limit" in the row's unit
            met = value is not None and value <= float(goal.split()[1])
        return {"row": name, "value": value, "anchor": anchor, "ratio": ratio, "unit": unit, "goal": goal, "met": met}

    start = record["startup"]
    bare, oxigraph = start["python -c pass"], start.get("oxigraph serve ready")
    plan = record["plan"]
    local, remote = plan["Composer.compose in-process"], plan["/cbrs/plan over the bridge"]
    memory = record["memory"]
    after = next(value for name, value in memory.items() if name.startswith("RSS after"))
    chain = next((v for k, v in record["composition"].items() if k.startswith("unsolvable")), None)
    return [
        row("cbrs --help, process start", start["cbrs --help"], bare, "s", "<= 0.3"),
        row("cbrs query, process start", start["cbrs query (:memory:)"], bare, "s", "<= 0.3"),
        row("cbrs query on an on-disk store, process start", start["cbrs query (on-disk store)"], bare, "s", "<= 0.3"),
        row("cbrs serve ready", start["cbrs serve ready (on-disk store)"], oxigraph, "s", "<= 0.5"),
        row("composition over a long chain pool", chain, None, "s", "composes", "error" not in record["composition"]),
        row("/cbrs/plan over the bridge, FetchMyPen", remote * 1000, local * 1000, "ms", "<= 20"),
        row(
            f"matchmaker RSS after {requirements} distinct requirements",
            after,
            None,
            "MB",
            "<= 500",
        ),
    ]


if __name__ == "__main__":
    main()
