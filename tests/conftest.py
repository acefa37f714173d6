from __future__ import annotations

import contextlib
import fcntl
import os
import re
import shutil
import socket
import subprocess
import sys
import tempfile
import time
import zlib
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO

import httpx
import pytest

from cbrs.kb import KnowledgeBase, Store
from cbrs.kb.namespaces import GraphName
from cbrs.kb.resources import ontology_dir

DATA = Path(__file__).parent / "data"
MINI_FILES = [DATA / "mini_ontology.ttl", DATA / "mini_services.ttl", DATA / "mini_requirements.ttl"]


def _find_oxigraph() -> str | None:
    """The Oxigraph server binary: installed by the test extra (PyPI oxigraph) beside this interpreter."""
    beside = Path(sys.executable).parent / "oxigraph"
    return str(beside) if beside.is_file() else shutil.which("oxigraph")


OXIGRAPH = _find_oxigraph()
NO_OXIGRAPH = "the oxigraph server binary is not installed (pip install oxigraph, or the test extra)"
BACKENDS = [pytest.param("embedded", id="embedded"), pytest.param("remote", id="remote")]


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line(
        "markers", "both_stores: run the module's tests that use store_location on the embedded and the remote store"
    )


# The files that took longest in a full run on two workers (14 s or more of 2,430 s, summed from the
# JUnit report of a run at f5e3ecf on a loaded machine), longest first; test_static where a cold mypy
# cache puts it (34 s; CI starts without one). They run before all others, so that the files left for
# the end, when one worker may be idle, are short ones; xdist's own order (most tests first,
# --loadscope-reorder) left the one-test files, the slowest of them 22 to 31 s (mypy, roslibpy's
# suite), for last. A file not named here only runs later.
LONGEST_FIRST = (
    "test_knowledge_driven",
    "test_run",
    "test_turtle_tasks_more",
    "test_remote_servers",
    "test_matchmaking_refinements",
    "test_browser",
    "test_turtle_tasks_arms",
    "test_standard_terms_updates",
    "test_cli",
    "test_bad_input",
    "test_static",
    "test_owlstc",
    "test_web_act",
    "test_kb16_request_copy",
    "test_serve",
    "test_turtle_tasks_colours",
    "test_hostile_queries",
    "test_access",
    "test_roslibpy_suite",
    "test_sim_scenarios",
    "test_recording",
    "test_install",
    "test_tasks_from_the_store",
    "test_home_people",
    "test_owl_api",
    "test_cold_match",
    "test_crash_safety",
    "test_perceived_belief",
    "test_conditions",
    "test_kb16_remote_load",
    "test_loader",
    "test_home_of_your_own",
    "test_status_effects",
    "test_late_answers",
    "test_blind_tasks3",
    "test_blind_tasks6",
    "test_no_base",
    "test_serve_clients",
    "test_base_choice_distance",
    "test_security_limits",
    "test_blind_tasks",
    "test_backup",
    "test_values",
    "test_live_components",
    "test_plan_unmapped",
    "test_grasp16_depth",
    "test_check",
    "test_readme",
    "test_upgrade",
    "test_batch",
)


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    """The longest files first (:data:`LONGEST_FIRST`), the rest in collection order; each file's tests
    stay together and in their order. The same order on every worker, as xdist requires."""
    rank = {name: index for index, name in enumerate(LONGEST_FIRST)}
    items.sort(key=lambda item: rank.get(item.path.stem, len(rank)))


def pytest_generate_tests(metafunc: pytest.Metafunc) -> None:
    # In a module marked both_stores, every test that (through its fixtures) uses store_location runs
    # twice; elsewhere store_location is the embedded in-memory store.
    if "store_location" in metafunc.fixturenames and metafunc.definition.get_closest_marker("both_stores"):
        metafunc.parametrize("store_location", BACKENDS, indirect=True)


# -- the Oxigraph server -----------------------------------------------------------------------------


@dataclass
class OxigraphServer:
    """An ``oxigraph serve`` process on a free loopback port, with its log (and data, if on disk) in ``directory``."""

    url: str
    directory: Path
    process: subprocess.Popen[bytes]
    log: IO[bytes]
    client: httpx.Client = field(default_factory=httpx.Client)

    def clear(self) -> None:
        response = self.client.post(
            self.url + "/update", content=b"DROP ALL", headers={"Content-Type": "application/sparql-update"}
        )
        response.raise_for_status()

    def stop(self) -> None:
        self.client.close()
        self.process.terminate()
        try:
            self.process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
        self.log.close()


def start_oxigraph(
    directory: Path, union_default_graph: bool = True, on_disk: bool = True, wait: float = 20.0
) -> OxigraphServer:
    """Start ``oxigraph serve`` in ``directory`` and wait (at most ``wait`` seconds) until it answers."""
    if OXIGRAPH is None:
        pytest.skip(NO_OXIGRAPH)
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    command = [OXIGRAPH, "serve", "--bind", f"127.0.0.1:{port}"]
    if on_disk:
        command += ["--location", str(directory / "data")]
    if union_default_graph:
        command.append("--union-default-graph")
    log = (directory / "server.log").open("wb")
    process = subprocess.Popen(command, cwd=directory, stdout=log, stderr=subprocess.STDOUT)
    server = OxigraphServer(f"http://127.0.0.1:{port}", directory, process, log)
    deadline = time.monotonic() + wait
    while time.monotonic() < deadline:
        if process.poll() is not None:
            raise RuntimeError(
                f"oxigraph serve exited with {process.returncode}: {(directory / 'server.log').read_text()}"
            )
        try:
            if server.client.get(server.url + "/", timeout=1.0).status_code == 200:
                return server
        except httpx.TransportError:
            time.sleep(0.05)
    server.stop()
    raise RuntimeError(f"oxigraph serve did not answer at {server.url} within {wait:g} s")


@pytest.fixture(scope="session")
def oxigraph_servers(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Callable[..., OxigraphServer]]:
    """Starts Oxigraph servers on demand (``oxigraph_servers(union_default_graph=False)``); all stop at the end."""
    started: list[OxigraphServer] = []

    def start(union_default_graph: bool = True, on_disk: bool = True) -> OxigraphServer:
        server = start_oxigraph(tmp_path_factory.mktemp("oxigraph"), union_default_graph, on_disk)
        started.append(server)
        return server

    yield start
    for server in started:
        server.stop()


@pytest.fixture(scope="session")
def oxigraph_server(oxigraph_servers: Callable[..., OxigraphServer]) -> OxigraphServer:
    """One Oxigraph server with a union default graph for the whole session, cleared before each test.

    It keeps its data in memory: on disk, the hundreds of DROP ALLs of a test run leave RocksDB
    tombstones that make every later write slower (the kb tests took about 10 s instead of 6 s). The
    servers test_remote_store.py starts without a union default graph run on disk.
    """
    return oxigraph_servers(on_disk=False)


@pytest.fixture
def remote_location(oxigraph_server: OxigraphServer) -> str:
    """The session's Oxigraph server, cleared: the location of an empty remote store."""
    oxigraph_server.clear()
    return oxigraph_server.url


@pytest.fixture
def store_location(request: pytest.FixtureRequest) -> str:
    """Where a test's store lives: ``:memory:``, or (in a both_stores module) the cleared server too."""
    if getattr(request, "param", "embedded") == "remote":
        return str(request.getfixturevalue("remote_location"))
    return ":memory:"


# -- Virtuoso 7 --------------------------------------------------------------------------------------


@dataclass
class VirtuosoServer:
    """Virtuoso 7 (Debian's virtuoso-opensource) on free loopback ports; ``url`` is its one SPARQL endpoint."""

    url: str
    own_graphs: frozenset[str]  # Virtuoso's system graphs, which clear() keeps
    process: subprocess.Popen[bytes]

    def graphs(self) -> set[str]:
        answer = httpx.post(
            self.url,
            data={"query": "SELECT DISTINCT ?g WHERE { GRAPH ?g { ?s ?p ?o } }"},
            headers={"Accept": "application/sparql-results+json"},
            timeout=30,
        )
        answer.raise_for_status()
        return {row["g"]["value"] for row in answer.json()["results"]["bindings"]}

    def clear(self) -> None:
        """Drop every graph but Virtuoso's own (a DROP ALL would drop those too): cbrs's graphs by name, and
        any other the store lists, until it lists none. The listing alone may miss graphs (Virtuoso can cut
        a costly result short without an error, its "anytime" queries): in one full-suite run the named
        queries differed on Virtuoso after earlier tests had filled it, and passed on every rerun."""
        named = {graph.iri for graph in GraphName}
        for _ in range(5):  # bounded: each round drops what the last listing still showed
            left = self.graphs() - self.own_graphs
            drops = " ; ".join(f"DROP SILENT GRAPH <{g}>" for g in sorted(left | named))
            named = set()
            answer = httpx.post(
                self.url, content=drops.encode(), headers={"Content-Type": "application/sparql-update"}, timeout=60
            )
            answer.raise_for_status()
            if not self.graphs() - self.own_graphs:
                return
        raise RuntimeError(f"Virtuoso at {self.url} still holds {sorted(self.graphs() - self.own_graphs)}")


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port: int = probe.getsockname()[1]
        return port


_VIRTUOSO_INI = Path("/etc/virtuoso-opensource-7/virtuoso.ini")
_VIRTUOSO_FILES = ("virtuoso.db", "virtuoso.trx", "virtuoso-temp.db")
"""What a stopped Virtuoso's database is: the files copied from the template database."""


def _virtuoso_template(server: str, isql: str) -> Path:
    """A database made by a Virtuoso started once on this machine and stopped, to start others from.

    A first start on an empty directory creates the database and installs the Conductor package, 20 to
    35 s; one on a copy of a stopped database answers in a few seconds. Made once per installed version
    (its binary and configuration), under a lock, since the test workers start theirs at the same time.
    """
    binary = Path(server).stat()
    key = f"{binary.st_size}-{int(binary.st_mtime)}-{zlib.crc32(_VIRTUOSO_INI.read_bytes()):08x}"
    root = Path(tempfile.gettempdir()) / f"cbrs-test-virtuoso-{os.getuid()}-{key}"
    root.mkdir(exist_ok=True)
    with (root / "lock").open("w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        made = root / "made"
        if not made.is_dir():
            scratch = Path(tempfile.mkdtemp(dir=root))
            with _virtuoso_process(server, isql, scratch):
                pass
            scratch.rename(made)
        return made


@contextlib.contextmanager
def virtuoso_running(directory: Path) -> Iterator[VirtuosoServer]:
    """A Virtuoso with its database in ``directory`` (a copy of :func:`_virtuoso_template`'s), its SPARQL
    user allowed to update; skipped when not installed (CI installs it). Stopped by its PID."""
    server, isql = shutil.which("virtuoso-t"), shutil.which("isql-vt")
    if server is None or isql is None or not _VIRTUOSO_INI.is_file():
        pytest.skip("Virtuoso is not installed (apt-get install virtuoso-opensource)")
    template = _virtuoso_template(server, isql)
    for name in _VIRTUOSO_FILES:
        if (template / name).is_file():
            shutil.copy2(template / name, directory / name)
    with _virtuoso_process(server, isql, directory) as started:
        yield started


@contextlib.contextmanager
def _virtuoso_process(server: str, isql: str, directory: Path) -> Iterator[VirtuosoServer]:
    """Virtuoso on ``directory``'s database (made there if absent) and free ports, until the block ends."""
    sql_port, http_port = _free_port(), _free_port()
    ini = _VIRTUOSO_INI.read_text()
    ini = ini.replace("/var/lib/virtuoso-opensource-7/db/", f"{directory}/")
    ini = re.sub(r"(?m)^ServerPort(\s*)=\s*1111$", rf"ServerPort\g<1>= {sql_port}", ini)
    ini = re.sub(r"(?m)^ServerPort(\s*)=\s*8890$", rf"ServerPort\g<1>= {http_port}", ini)
    (directory / "virtuoso.ini").write_text(ini)
    log = (directory / "out.log").open("wb")
    process = subprocess.Popen(
        [server, "+configfile", str(directory / "virtuoso.ini"), "+foreground"],
        cwd=directory,
        stdout=log,
        stderr=subprocess.STDOUT,
    )
    url = f"http://127.0.0.1:{http_port}/sparql"
    try:
        deadline = time.monotonic() + 60
        while True:
            assert process.poll() is None, (directory / "out.log").read_text()
            try:
                if httpx.get(url, params={"query": "ASK {}"}, timeout=2).status_code == 200:
                    break
            except httpx.TransportError:
                pass
            assert time.monotonic() < deadline, "Virtuoso did not answer within 60 s"
            time.sleep(0.2)
        grant = 'grant SPARQL_UPDATE to "SPARQL";'
        subprocess.run(
            [isql, str(sql_port), "dba", "dba", f"exec={grant}"], check=True, timeout=30, capture_output=True
        )
        started = VirtuosoServer(url, frozenset(), process)
        yield VirtuosoServer(url, frozenset(started.graphs()), process)
    finally:
        process.terminate()
        try:
            process.wait(timeout=20)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait(timeout=10)
        log.close()


@pytest.fixture(scope="session")
def virtuoso_server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[VirtuosoServer]:
    """One Virtuoso for the session (see :func:`virtuoso_running`)."""
    with virtuoso_running(tmp_path_factory.mktemp("virtuoso")) as server:
        yield server


# -- knowledge bases ---------------------------------------------------------------------------------


def make_mini_kb(location: str = ":memory:") -> KnowledgeBase:
    """The core ontology plus the mini test data (not the bundled home data)."""
    kb = KnowledgeBase(Store.open(location))
    kb.load([ontology_dir() / "core.ttl"], graph="ontology")
    kb.load(MINI_FILES)
    return kb


@pytest.fixture
def mini_kb(store_location: str) -> Iterator[KnowledgeBase]:
    kb = make_mini_kb(store_location)
    yield kb
    kb.close()


@pytest.fixture(scope="session")
def bundled_kb() -> KnowledgeBase:
    """A seeded in-memory knowledge base, shared: tests that use it must not write to it."""
    return KnowledgeBase.open(":memory:")


@pytest.fixture
def fresh_bundled_kb(store_location: str) -> Iterator[KnowledgeBase]:
    kb = KnowledgeBase.open(store_location)
    yield kb
    kb.close()
