"""A file of two advertisements, one of them deregistered, brought back in line with the store in one
command. Before, ``cbrs register FILE`` refused it (the other advertisement is registered: "update it
instead") and ``cbrs register --update FILE`` refused it too (the deregistered one is not registered), so
the only way was to deregister the other and register the file again, in two transactions.
``kb.registry.sync`` (``cbrs register --update``) registers what is new and replaces what is registered,
in one transaction; what it refuses leaves the store as it was. An OWL-S file (``cbrs load``) is not
registered as a sync only: the refusals name ``cbrs register --update FILE``, which brings the store in
line with it in one transaction (tests/test_register_update_owls.py).

Every test compares the store's triples graph by graph, on the embedded and the remote store."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from cbrs.kb import InvalidDescriptionError, KnowledgeBase, NotFoundError, RdfParseError
from cbrs.kb.errors import AlreadyRegisteredError, OutsideRegistryError
from cbrs.kb.namespaces import OWL

from .conftest import MINI_FILES, make_mini_kb, ontology_dir
from .test_cli import run
from .test_deregister_owls import LAB, OWLS, _pair, triples_by_graph

pytestmark = pytest.mark.both_stores

EX = "http://example.org/mini#"
TWO = """@prefix cbrs: <https://w3id.org/cbrs/core#> . @prefix ex: <http://example.org/mini#> .
ex:TrackA a cbrs:DynamicPerceptionComponent ; cbrs:deviceName "Camera1" ; cbrs:serviceName "TrackA" ;
    cbrs:hasOWLSModel [ cbrs:hasInput [ cbrs:parameterType ex:MarkerColour ] ;
                        cbrs:hasOutput [ cbrs:parameterType ex:Location ] ] ;
    cbrs:hasQoSModel ex:SharedQoS .
ex:TrackB a cbrs:DynamicPerceptionComponent ; cbrs:deviceName "Camera2" ; cbrs:serviceName "TrackB" ;
    cbrs:hasOWLSModel [ cbrs:hasOutput [ cbrs:parameterType ex:Location ] ] ;
    cbrs:hasQoSModel ex:SharedQoS .
ex:SharedQoS cbrs:responseTime 0.2 .
"""


@pytest.fixture
def kb(store_location: str) -> Iterator[KnowledgeBase]:
    kb = make_mini_kb(store_location)
    kb.load([OWLS / "ontology"])
    yield kb
    kb.close()


def _file(tmp_path: Path, text: str = TWO, name: str = "two.ttl") -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


def _sync(kb: KnowledgeBase, path: Path) -> tuple[list[str], list[str]]:
    return kb.registry.sync(path.read_bytes(), str(path))


def test_the_deregistered_one_comes_back_and_the_other_is_replaced(kb: KnowledgeBase, tmp_path: Path) -> None:
    path = _file(tmp_path)
    before = triples_by_graph(kb)
    kb.registry.register(path.read_bytes(), str(path))
    registered = triples_by_graph(kb)
    kb.registry.deregister(EX + "TrackA")
    partial = triples_by_graph(kb)
    assert partial != registered
    with pytest.raises(AlreadyRegisteredError, match="TrackB"):
        kb.registry.register(path.read_bytes(), str(path))
    with pytest.raises(NotFoundError, match="TrackA"):
        kb.registry.update(path.read_bytes(), str(path))
    assert triples_by_graph(kb) == partial
    assert _sync(kb, path) == ([EX + "TrackA"], [EX + "TrackB"])
    assert triples_by_graph(kb) == registered
    assert _sync(kb, path) == ([], [EX + "TrackA", EX + "TrackB"])  # the same file again changes nothing
    assert triples_by_graph(kb) == registered
    for name in ("TrackA", "TrackB"):
        kb.registry.deregister(EX + name)
    assert triples_by_graph(kb) == before
    assert _sync(kb, path) == ([EX + "TrackA", EX + "TrackB"], [])  # nothing registered: both are new
    assert triples_by_graph(kb) == registered


def test_an_edited_file_gives_the_store_of_the_edited_file_alone(kb: KnowledgeBase, tmp_path: Path) -> None:
    """TrackA deregistered, then the file edited (TrackB's output and the shared QoS): one sync gives
    exactly what registering the edited file on the store without either would give."""
    original = _file(tmp_path)
    edited = _file(
        tmp_path,
        TWO.replace(
            "ex:Location ] ] ;\n    cbrs:hasQoSModel ex:SharedQoS .\nex:Shared",
            "ex:MarkerColour ] ] ;\n    cbrs:hasQoSModel ex:SharedQoS .\nex:Shared",
        ).replace("0.2", "0.5"),
        "edited.ttl",
    )
    assert edited.read_text(encoding="utf-8").count("ex:MarkerColour") == 2
    kb.registry.register(edited.read_bytes(), str(original))  # named as the file it replaces: the same base
    edited_alone = triples_by_graph(kb)
    for name in ("TrackA", "TrackB"):
        kb.registry.deregister(EX + name)
    kb.registry.register(original.read_bytes(), str(original))
    kb.registry.deregister(EX + "TrackA")
    assert kb.registry.sync(edited.read_bytes(), str(original)) == ([EX + "TrackA"], [EX + "TrackB"])
    assert triples_by_graph(kb) == edited_alone
    assert [p.type for p in kb.description(EX + "TrackB").outputs] == [EX + "MarkerColour"]


def test_a_refused_sync_changes_nothing(kb: KnowledgeBase, tmp_path: Path) -> None:
    """What is refused is refused before anything is written: an invalid description beside a new and a
    registered one, another resource (a device) by a new advertisement's IRI, and an advertisement that
    another graph holds (which the sync would register a second time)."""
    path = _file(tmp_path)
    kb.registry.register(path.read_bytes(), str(path))
    kb.registry.deregister(EX + "TrackA")
    partial = triples_by_graph(kb)
    invalid = _file(tmp_path, TWO.replace('cbrs:serviceName "TrackB" ;', ""), "invalid.ttl")
    with pytest.raises(InvalidDescriptionError, match="service name"):
        _sync(kb, invalid)
    assert triples_by_graph(kb) == partial
    device = _file(tmp_path, TWO.replace("ex:TrackA a", "ex:Camera1 a"), "device.ttl")
    with pytest.raises(AlreadyRegisteredError, match="Camera1"):
        _sync(kb, device)
    assert triples_by_graph(kb) == partial
    other = TWO.replace("TrackA", "TrackC").replace("TrackB", "TrackD")
    kb.load([_file(tmp_path, f"@prefix owl: <{OWL}> .\n{other}ex:Widget a owl:Class .\n", "lab.ttl")])
    loaded = triples_by_graph(kb)  # a file that declares a class: cbrs load put TrackC into graph:ontology
    with pytest.raises(OutsideRegistryError, match="TrackC"):
        _sync(kb, _file(tmp_path, TWO.replace("TrackA", "TrackC"), "c.ttl"))
    assert triples_by_graph(kb) == loaded


def test_the_command_says_which_it_registered_and_which_it_updated(tmp_path: Path) -> None:
    """On a store directory of its own, once: the mini data is loaded into it, whatever the module's stores."""
    location = str(tmp_path / "store")
    assert run("load", str(ontology_dir() / "core.ttl"), *map(str, MINI_FILES), store=location)[0] == 0
    path = _file(tmp_path)
    # the names as the browser shows them (no prefix is declared for the file's namespace), and they name them
    assert run("register", str(path), store=location) == (0, "registered mini:TrackA\nregistered mini:TrackB\n")
    assert EX + "TrackA" in run("show", "mini:TrackA", "--json", store=location)[1]
    before = run("query", "SELECT (COUNT(*) AS ?n) WHERE { GRAPH ?g { ?s ?p ?o } }", store=location)
    assert run("deregister", EX + "TrackA", store=location)[0] == 0
    code, out = run("register", str(path), store=location)
    assert code == 1 and f"already registered; update it instead: cbrs register --update {path}" in out
    synced = run("register", "--update", str(path), store=location)
    assert synced == (0, "registered mini:TrackA\nupdated mini:TrackB\n")
    assert run("query", "SELECT (COUNT(*) AS ?n) WHERE { GRAPH ?g { ?s ?p ?o } }", store=location) == before


def test_an_owls_file_is_brought_in_line_by_one_command(kb: KnowledgeBase, tmp_path: Path) -> None:
    """``cbrs load`` of the file again is refused (the file's triples are not all stored: the merge check),
    and so are registering and updating it (registration converts OWL-S only as a sync): each refusal
    names ``cbrs register --update FILE``, and following it gives the store of the file loaded once
    (tests/test_register_update_owls.py has the rest)."""
    pair = _file(tmp_path, _pair(), "pair.owls")
    kb.load([pair])
    loaded = triples_by_graph(kb)
    kb.registry.deregister(LAB + "A")
    partial = triples_by_graph(kb)
    with pytest.raises(RdfParseError, match="cbrs register --update FILE replaces it"):
        kb.load([pair])
    for attempt in (kb.registry.update, kb.registry.register):
        with pytest.raises(InvalidDescriptionError, match=f"cbrs register --update {pair} replaces it"):
            attempt(pair.read_bytes(), str(pair))
    assert triples_by_graph(kb) == partial
    assert kb.registry.sync(pair.read_bytes(), str(pair)) == ([LAB + "A"], [LAB + "B"])
    assert triples_by_graph(kb) == loaded


def test_a_node_only_the_updated_advertisements_share_takes_its_new_values(kb: KnowledgeBase, tmp_path: Path) -> None:
    """ex:SharedQoS is both advertisements' QoS model, and the file gives it a new response time. What
    they own is read as deregistering them one after the other removes it, so the shared node goes with
    the second and comes back as the file gives it now; read for each alone, it stayed, and the two
    advertisements had two response times."""
    _sync(kb, _file(tmp_path))
    faster = _file(tmp_path, TWO.replace("cbrs:responseTime 0.2", "cbrs:responseTime 0.1"), "faster.ttl")
    assert _sync(kb, faster) == ([], [EX + "TrackA", EX + "TrackB"])
    for name in ("TrackA", "TrackB"):
        assert [q.value for q in kb.description(EX + name).qos] == [0.1]
    kb.registry.deregister(EX + "TrackA")
    kb.registry.deregister(EX + "TrackB")
    registered = triples_by_graph(kb)
    _sync(kb, faster)
    kb.registry.deregister(EX + "TrackA")
    kb.registry.deregister(EX + "TrackB")
    assert triples_by_graph(kb) == registered
