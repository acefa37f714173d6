"""Benchmark: the HTTP requests a ``cbrs plan`` and a ``cbrs run`` make against a remote store, and their wall time.

Run: python bench/remote_run.py [--repeat N] [--task TASK ...] [--source DIR ...]. It seeds a scratch
store, starts ``cbrs serve`` over it on a free loopback port with an update token, and runs each command
as its own process, ``cbrs --store http://127.0.0.1:PORT plan TASK`` (``--no-store``: a plan writes
nothing, so every repeat reads the same store) and ``cbrs --store ... run TASK --seed 0``, counting the
requests it sends by kind: the named query (``queries/<name>.rq``), ``quads()`` and the other queries
cbrs writes itself, a belief write (whole, or data operations only) or another update. The anchor is the
same command on an embedded copy of the store, measured in the same run. ``--source DIR`` (repeatable)
measures that version of cbrs instead of this checkout (a ``git archive COMMIT | tar -x -C DIR``
export), each with a store it seeded and a ``cbrs serve`` of its own, the versions' commands
alternating, so a before and an after are back to back. The servers are stopped by their PIDs at the
end.
"""

from __future__ import annotations

import argparse
import collections
import contextlib
import json
import os
import platform
import shutil
import socket
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from urllib.parse import parse_qs

TOKEN = "bench-remote-run"
TASKS = ("req:RobotSelfPosition", "req:FetchMyPen", "act:RobotArmServeACup")


def _child(out: Path, argv: list[str], latency: float) -> None:
    """Run ``cbrs ARGV`` in this process, counting the requests its remote store sends, each delayed by
    ``latency`` seconds (a network's round trip beyond loopback's); write them to ``out``."""
    from cbrs.cli import cli
    from cbrs.kb import remote_store
    from cbrs.kb.queries import QueryLibrary
    from cbrs.kb.resources import query_dir

    library = QueryLibrary(query_dir())
    names = {library.get(name).text: name for name in library.names()}
    counts: collections.Counter[str] = collections.Counter()
    spent: collections.Counter[str] = collections.Counter()  # ms waited for the answers, by kind
    post = remote_store.RemoteStore._post

    def counted(
        self: remote_store.RemoteStore,
        url: str,
        body: str,
        content_type: str,
        original: str | None,
        *args: object,
        **kwargs: object,
    ) -> object:
        kind = _kind(body, content_type, original, names)
        counts[kind] += 1
        start = time.perf_counter()
        time.sleep(latency)
        try:
            return post(self, url, body, content_type, original, *args, **kwargs)  # type: ignore[arg-type]
        finally:
            spent[kind] += (time.perf_counter() - start) * 1000

    remote_store.RemoteStore._post = counted  # type: ignore[method-assign]
    code = 0
    try:
        cli.main(argv, prog_name="cbrs", standalone_mode=False)
    except SystemExit as stop:
        code = stop.code if isinstance(stop.code, int) else 1
    except Exception:  # a crash is no figure: the parent stops, naming the command
        code = 2
        raise
    finally:
        out.write_text(json.dumps({"counts": counts, "ms": spent, "exit": code}))


def _kind(body: str, content_type: str, original: str | None, names: dict[str, str]) -> str:
    """What a request is: an update, a named query asked alone, several asked at once, a pattern lookup."""
    if content_type == "application/sparql-update":
        if "<https://w3id.org/cbrs/graph/world>" not in body:
            return "update"  # the plan's, say
        data = body.lstrip().startswith(("DELETE DATA", "INSERT DATA"))
        return "belief write, data" if data else "belief write, whole"
    if original is not None and original in names:
        return names[original]
    text = original or (parse_qs(body).get("query", [body])[0] if content_type.endswith("urlencoded") else body)
    if "?cbrs__part" in text:
        return f"{text.count('AS ?cbrs__part)')} queries at once"
    return "quads()" if "?s ?p ?o ?g" in text else "other query"


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


@contextmanager
def cbrs_serve(store: Path, env: dict[str, str]) -> Iterator[str]:
    """``cbrs serve`` over ``store`` on a free loopback port, its URL; stopped by its PID."""
    port = _free_port()
    argv = [sys.executable, "-m", "cbrs", "--store", str(store), "serve", "--port", str(port), "--bridge-port", "0"]
    process = subprocess.Popen(argv, env=env, cwd=store.parent, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    url = f"http://127.0.0.1:{port}"
    try:
        import httpx

        for _ in range(300):  # at most 30 s
            try:
                if httpx.post(url + "/sparql", data={"query": "ASK {}"}, timeout=1).status_code == 200:
                    break
            except httpx.HTTPError:
                pass
            if process.poll() is not None:
                raise SystemExit(f"cbrs serve exited with {process.returncode}")
            time.sleep(0.1)
        else:
            raise SystemExit("cbrs serve did not answer within 30 s")
        yield url
    finally:
        process.terminate()
        try:
            process.wait(10)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()


def _round_trip_ms(url: str, repeat: int = 50) -> float:
    """The median time of a query that asks nothing of the store, ``ASK {}``: what a request costs alone."""
    import httpx

    times = []
    with httpx.Client() as client:
        for _ in range(repeat):
            start = time.perf_counter()
            client.post(url + "/sparql", data={"query": "ASK {}"}).raise_for_status()
            times.append((time.perf_counter() - start) * 1000)
    return statistics.median(times)


def measure(
    argv: list[str], env: dict[str, str], scratch: Path, latency: float
) -> tuple[float, dict[str, int], dict[str, float], int]:
    """Wall seconds of ``cbrs ARGV`` in a process of its own, the requests it sent by kind and the ms it
    waited for their answers, its exit status."""
    out = scratch / "counts.json"
    script = str(Path(__file__).resolve())
    command = [sys.executable, script, "--child", str(out), "--latency", str(latency), "--", *argv]
    start = time.perf_counter()
    # run from the scratch folder: `-m cbrs` puts the working directory first on the path, so from inside a
    # checkout every --source would run the checkout's code
    subprocess.run(command, env=env, cwd=scratch, check=False, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    wall = time.perf_counter() - start
    found = json.loads(out.read_text())
    return wall, found["counts"], found["ms"], found["exit"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--repeat", type=int, default=3, help="runs of each command (median wall time)")
    parser.add_argument("--task", action="append", help=f"tasks (default: {', '.join(TASKS)})")
    parser.add_argument("--source", action="append", default=[], type=Path, help="measure this checkout instead")
    parser.add_argument("--kinds", action="store_true", help="print the requests of each command by kind")
    parser.add_argument("--latency", type=float, default=0.0, help="ms added to each request (a network's RTT)")
    parser.add_argument("--child", type=Path, help=argparse.SUPPRESS)
    arguments, rest = parser.parse_known_args()
    if arguments.child is not None:
        _child(arguments.child, [a for a in rest if a != "--"], arguments.latency / 1000)
        return
    tasks = arguments.task or list(TASKS)
    sources: list[Path | None] = [source.resolve() for source in arguments.source] or [None]
    print(f"machine: {platform.platform()}, {os.cpu_count()} cores, python {platform.python_version()}")
    print(
        f"inputs: the bundled store; tasks {', '.join(tasks)}; plan --no-store, run --seed 0; repeat {arguments.repeat}"
    )
    if arguments.latency:
        print(f"each request to the server delayed by {arguments.latency:g} ms in the client (a network's round trip)")
    print(f"load average at the start: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    with tempfile.TemporaryDirectory() as folder, contextlib.ExitStack() as servers:
        scratch = Path(folder)
        base = dict(os.environ, CBRS_UPDATE_TOKEN=TOKEN)
        base.pop("CBRS_STORE", None)
        versions = []
        for number, source in enumerate(sources):
            env = dict(base, PYTHONPATH=str(source)) if source else base
            seeded = scratch / f"seeded{number}"  # each version seeds its own: the bundled files may differ
            subprocess.run(
                [sys.executable, "-m", "cbrs", "--store", str(seeded), "init"],
                env=env,
                cwd=scratch,  # not the checkout's code first on the path (see measure)
                check=True,
                stdout=subprocess.DEVNULL,
            )
            served, embedded = scratch / f"served{number}", scratch / f"embedded{number}"
            shutil.copytree(seeded, served)
            shutil.copytree(seeded, embedded)
            url = servers.enter_context(cbrs_serve(served, env))
            versions.append((str(source or "this checkout"), env, url, embedded))
            trip = _round_trip_ms(url)
            print(f"{versions[-1][0]}: cbrs serve over an on-disk store at {url} (loopback; ASK {{}} {trip:.1f} ms)")
        print("anchor: the same command on an embedded on-disk copy of the store, in the same run")
        rows = []
        for task in tasks:
            for command in (["plan", task, "--no-store"], ["run", task, "--seed", "0"]):
                walls: dict[tuple[str, str], list[float]] = collections.defaultdict(list)
                waits: dict[str, list[float]] = collections.defaultdict(list)
                kinds: dict[str, dict[str, int]] = {}
                kind_ms: dict[str, dict[str, float]] = {}
                for _ in range(arguments.repeat):
                    for label, env, url, embedded in versions:  # the versions alternate
                        for where, store in (("remote", url), ("embedded", str(embedded))):
                            delay = arguments.latency if where == "remote" else 0.0
                            wall, counts, ms, code = measure(["--store", store, *command], env, scratch, delay)
                            if code:
                                raise SystemExit(f"{label}: cbrs --store {store} {' '.join(command)} exited {code}")
                            walls[(label, where)].append(wall)
                            if where == "remote":
                                kinds[label], kind_ms[label] = counts, ms
                                waits[label].append(sum(ms.values()) / 1000)
                for label, *_ in versions:
                    remote = statistics.median(walls[(label, "remote")])
                    anchor = statistics.median(walls[(label, "embedded")])
                    waited = statistics.median(waits[label])
                    rows.append((" ".join(command[:2]), label, sum(kinds[label].values()), waited, remote, anchor))
                    if arguments.kinds:
                        ranked = sorted(kinds[label].items(), key=lambda kind: -kind[1])
                        shown = ", ".join(
                            f"{k} {n} ({kind_ms[label][k]:.0f} ms, {kind_ms[label][k] / n:.0f} each)" for k, n in ranked
                        )
                        print(f"  {' '.join(command[:2])} [{label}]: {shown}")
    print()
    head = f"{'requests':>8} {'waited s':>8} {'remote s':>8} {'embedded s':>10} {'ratio':>5}"
    print(f"{'command':<28} {'version':<20} {head}")
    for text, label, requests, waited, remote, anchor in rows:
        figures = f"{requests:>8} {waited:>8.2f} {remote:>8.2f} {anchor:>10.2f} {remote / anchor:>5.2f}"
        print(f"{text:<28} {label[-20:]:<20} {figures}")
    print("waited: the time the command waited for the server's answers (median); remote, embedded: its wall time")
    print(f"load average at the end: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    main()
