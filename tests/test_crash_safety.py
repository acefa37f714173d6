"""Crash safety: a process SIGKILLed in the middle of a large load or a long update leaves the store
holding all or nothing of that write, and the store still answers queries and takes writes.

Each trial copies a closed on-disk store (the bundled knowledge base plus a join's base data), runs one
write in a child process (tests/helpers_crash.py), kills it a seeded-random delay after a milestone the
child prints, reopens the store here and takes a census of the write through three of Oxigraph's
indexes (every quad; a predicate's triples by SPARQL; one object's subject): a half-applied write
would show in at least one of them. A kill after the write was acknowledged (the CLI's "loaded" line,
HTTP 200) must leave all of it: the write is durable once acknowledged, before any flush.
"""

from __future__ import annotations

import queue
import random
import shutil
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import httpx
import pyoxigraph as ox
import pytest

from cbrs.kb import KnowledgeBase, Store

HELPER = Path(__file__).with_name("helpers_crash.py")
WAIT = 30.0  # bound on every wait for the child; the trials take a few seconds each
TOKEN = "crash-test-token"
SEED = 9
ITEMS = 30_000  # the generated file: two triples per item; parsing and writing it takes about 2 s here
SIDE = 200  # the update joins SIDE x SIDE base nodes into SIDE**2 new triples
# A kill after the acknowledgement finds the whole write whatever its size: those trials write less (a
# tenth of the file, a sixteenth of the join), so as not to wait seconds for the write to end first.
ACKNOWLEDGED_ITEMS = 3_000
ACKNOWLEDGED_SIDE = 50
ALL_QUADS = "SELECT (COUNT(*) AS ?n) WHERE { GRAPH ?g { ?s ?p ?o } }"  # cbrs keeps every triple in a named graph
BASE = ox.NamedNode("urn:crash:base")


def join_update(side: int = SIDE) -> str:
    """The update joining the first ``side`` left and right base nodes into side**2 new triples."""
    return (
        "INSERT { GRAPH <urn:crash:join> { ?a <urn:crash:pair> ?b } } "
        "WHERE { GRAPH <urn:crash:base> { ?a <urn:crash:left> ?x . ?b <urn:crash:right> ?y "
        f"FILTER (?x < {side} && ?y < {side}) }} }}"
    )


@dataclass(frozen=True)
class Write:
    """What one operation adds, and the queries that find it through different indexes."""

    quads: int  # quads the whole operation adds
    rows: int  # what ``count`` answers once it is all there
    count: str  # SELECT (COUNT(*) AS ?n): the operation's triples by predicate
    first: str  # ASK: the operation's first triple, by its object
    last: str  # ASK: its last one


def load_write(items: int) -> Write:
    """What loading the file of ``items`` items adds."""
    return Write(
        quads=2 * items,
        rows=items,
        count="SELECT (COUNT(*) AS ?n) WHERE { ?s <urn:crash:rank> ?r }",
        first='ASK { ?s ?p "item 0" }',
        last=f'ASK {{ ?s ?p "item {items - 1}" }}',
    )


def update_write(side: int) -> Write:
    """What :func:`join_update` of ``side`` adds."""
    return Write(
        quads=side * side,
        rows=side * side,
        count="SELECT (COUNT(*) AS ?n) WHERE { GRAPH <urn:crash:join> { ?a <urn:crash:pair> ?b } }",
        first="ASK { ?a <urn:crash:pair> <urn:crash:right0> }",
        last=f"ASK {{ <urn:crash:left{side - 1}> <urn:crash:pair> <urn:crash:right{side - 1}> }}",
    )


@dataclass(frozen=True)
class Census:
    quads: int
    rows: int
    first: bool
    last: bool


@dataclass(frozen=True)
class Template:
    """A closed store to copy for each trial, and what it answers before any trial's write."""

    path: Path
    quads: int
    advertisements: list[str]


def _delay(name: str, low: float, high: float) -> float:
    return round(random.Random(f"{SEED}-{name}").uniform(low, high), 2)


# (milestone the child prints, seconds after it to kill, whether the write was acknowledged by then)
LOAD_KILLS = [
    pytest.param("started", _delay("parse", 0.0, 0.3), False, id="load-while-parsing"),
    pytest.param("writing", _delay("load-early", 0.0, 0.3), False, id="load-early-in-write"),
    pytest.param("writing", _delay("load-late", 0.3, 1.0), False, id="load-late-in-write"),
    pytest.param("loaded", 0.0, True, id="load-after-cli-said-loaded"),
]
UPDATE_KILLS = [
    pytest.param("writing", _delay("update-early", 0.0, 0.25), False, id="update-early"),
    pytest.param("writing", _delay("update-late", 0.25, 0.5), False, id="update-late"),
    pytest.param("done", 0.0, True, id="update-after-it-returned"),
]
SERVED_KILLS = [pytest.param(_delay("served", 0.1, 0.4), id="served-update")]


class Child:
    """A helper process whose output lines are read on a thread, so every wait for one is bounded."""

    def __init__(self, *args: str, log: Path) -> None:
        self.log = log.open("wb")
        self.process = subprocess.Popen(
            [sys.executable, "-u", str(HELPER), *args], stdout=subprocess.PIPE, stderr=self.log, text=True
        )
        self.lines: queue.Queue[str] = queue.Queue()
        self.seen: list[str] = []
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self) -> None:
        assert self.process.stdout is not None
        for line in self.process.stdout:
            self.lines.put(line.strip())

    def wait_for(self, prefix: str) -> str:
        deadline = time.monotonic() + WAIT
        while time.monotonic() < deadline:
            try:
                line = self.lines.get(timeout=0.1)
            except queue.Empty:
                if self.process.poll() is not None and self.lines.empty():
                    break
                continue
            self.seen.append(line)
            if line.startswith(prefix):
                return line
        raise AssertionError(f"the child never printed {prefix!r}; it printed {self.seen}: {self._stderr()}")

    def kill(self) -> None:
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGKILL)
        self.process.wait(WAIT)
        self._reader.join(WAIT)
        self.log.close()

    def _stderr(self) -> str:
        self.log.flush()
        return Path(self.log.name).read_text(errors="replace")[-2000:]


@pytest.fixture(scope="module")
def template(tmp_path_factory: pytest.TempPathFactory) -> Template:
    path = tmp_path_factory.mktemp("crash") / "template"
    kb = KnowledgeBase.open(path)
    kb.store.add(
        ox.Quad(ox.NamedNode(f"urn:crash:{side}{i}"), ox.NamedNode(f"urn:crash:{side}"), ox.Literal(i), BASE)
        for side in ("left", "right")
        for i in range(SIDE)
    )
    made = Template(path, _number(kb.store, ALL_QUADS), _advertisements(kb))
    kb.close()
    return made


@pytest.fixture(scope="module")
def item_files(tmp_path_factory: pytest.TempPathFactory) -> dict[int, Path]:
    """The generated files, by their number of items."""
    folder = tmp_path_factory.mktemp("crash-data")
    return {items: _item_file(folder / f"items-{items}.nt", items) for items in (ITEMS, ACKNOWLEDGED_ITEMS)}


def _item_file(path: Path, items: int) -> Path:
    with path.open("w", encoding="utf-8") as out:
        for i in range(items):
            out.write(f'<urn:crash:item{i}> <urn:crash:rank> "{i}"^^<http://www.w3.org/2001/XMLSchema#integer> .\n')
            out.write(f'<urn:crash:item{i}> <http://www.w3.org/2000/01/rdf-schema#label> "item {i}" .\n')
    return path


@pytest.fixture
def store_copy(template: Template, tmp_path: Path) -> Iterator[Path]:
    path = tmp_path / "store"
    shutil.copytree(template.path, path)
    yield path


def _advertisements(kb: KnowledgeBase) -> list[str]:
    return sorted(row["service"].value for row in kb.select("advertisements"))


def _number(store: Store, query: str) -> int:
    (row,) = list(store.query(query))  # type: ignore[arg-type]
    return int(row["n"].value)


def _census(store: Store, write: Write) -> Census:
    quads = _number(store, ALL_QUADS)
    return Census(quads, _number(store, write.count), bool(store.query(write.first)), bool(store.query(write.last)))


def _check_reopened(location: Path, template: Template, write: Write, acknowledged: bool, trial: str) -> str:
    """Reopen the killed child's store: all or nothing of ``write`` (all if acknowledged), queries answer,
    and a new write sticks. Returns which of the two it was."""
    nothing = Census(template.quads, 0, False, False)
    everything = Census(template.quads + write.quads, write.rows, True, True)
    kb = KnowledgeBase(Store.open(location))
    try:
        census = _census(kb.store, write)
        assert census in ((everything,) if acknowledged else (nothing, everything)), (
            f"{trial}: the store holds part of the write: {census}; nothing is {nothing}, all is {everything}"
        )
        assert _advertisements(kb) == template.advertisements
        kb.update("INSERT DATA { GRAPH <urn:crash:after> { <urn:crash:after> <urn:crash:wrote> 1 } }")
    finally:
        kb.close()
    reopened = Store.open(location)
    try:
        assert _number(reopened, ALL_QUADS) == census.quads + 1
        assert bool(reopened.query("ASK { <urn:crash:after> <urn:crash:wrote> 1 }"))
    finally:
        reopened.close()
    return "all" if census == everything else "nothing"


@pytest.mark.parametrize(("milestone", "delay", "acknowledged"), LOAD_KILLS)
def test_load_killed_mid_way_is_all_or_nothing(
    template: Template,
    item_files: dict[int, Path],
    store_copy: Path,
    tmp_path: Path,
    milestone: str,
    delay: float,
    acknowledged: bool,
) -> None:
    items = ACKNOWLEDGED_ITEMS if acknowledged else ITEMS
    child = Child("load", str(store_copy), str(item_files[items]), log=tmp_path / "child.log")
    try:
        child.wait_for(milestone)
        time.sleep(delay)
    finally:
        child.kill()
    trial = f"load killed {delay} s after {milestone}"
    outcome = _check_reopened(store_copy, template, load_write(items), acknowledged, trial)
    print(f"load killed {delay} s after {milestone!r}: {outcome}")


@pytest.mark.parametrize(("milestone", "delay", "acknowledged"), UPDATE_KILLS)
def test_update_killed_mid_way_is_all_or_nothing(
    template: Template, store_copy: Path, tmp_path: Path, milestone: str, delay: float, acknowledged: bool
) -> None:
    side = ACKNOWLEDGED_SIDE if acknowledged else SIDE
    child = Child("update", str(store_copy), join_update(side), log=tmp_path / "child.log")
    try:
        child.wait_for(milestone)
        time.sleep(delay)
    finally:
        child.kill()
    trial = f"update killed {delay} s after {milestone}"
    outcome = _check_reopened(store_copy, template, update_write(side), acknowledged, trial)
    print(f"update killed {delay} s after {milestone!r}: {outcome}")


@pytest.mark.parametrize("delay", SERVED_KILLS)
def test_server_killed_during_an_update_request_is_all_or_nothing(
    template: Template, store_copy: Path, tmp_path: Path, delay: float
) -> None:
    child = Child("serve", str(store_copy), TOKEN, log=tmp_path / "child.log")
    answers: list[int | str] = []
    try:
        port = int(child.wait_for("port ").split()[1])

        def post() -> None:
            try:
                response = httpx.post(
                    f"http://127.0.0.1:{port}/update",
                    content=join_update().encode("utf-8"),
                    headers={"Content-Type": "application/sparql-update", "Authorization": f"Bearer {TOKEN}"},
                    timeout=WAIT,
                )
                answers.append(response.status_code)
            except httpx.TransportError as error:  # the server died with the request in flight
                answers.append(type(error).__name__)

        request = threading.Thread(target=post)
        request.start()
        child.wait_for("writing")
        time.sleep(delay)
    finally:
        child.kill()
    request.join(WAIT)
    assert len(answers) == 1 and (answers[0] == 204 or isinstance(answers[0], str)), answers
    acknowledged = answers[0] == 204
    outcome = _check_reopened(
        store_copy, template, update_write(SIDE), acknowledged, f"server killed {delay} s into /update"
    )
    print(f"server killed {delay} s into /update (client saw {answers[0]}): {outcome}")
