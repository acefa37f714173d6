"""``cbrs register --update FILE`` of an OWL-S file: one command, one transaction. Before, it was refused
with the two commands that brought the store in line (``cbrs deregister`` of each service still loaded,
then ``cbrs load FILE``), and a load that failed after the deregistrations left the services gone.
Now the registry converts the file as ``cbrs load`` does and replaces what its earlier load gave with
what it gives now; a file that cannot be converted or checked leaves the store as it was.

Every test compares the store's triples graph by graph (graph:entailed included) with a store where the
file was loaded once, on the embedded and the remote store."""

from __future__ import annotations

from pathlib import Path

import pytest

from cbrs.kb import InvalidDescriptionError, KnowledgeBase, RdfParseError
from cbrs.kb.errors import AlreadyRegisteredError

from .test_cli import run
from .test_deregister_owls import LAB, OWLS, _pair, triples_by_graph
from .test_register_update_partial import _file, kb

__all__ = ["kb"]  # the fixture, used by name

pytestmark = pytest.mark.both_stores


def _sync(kb: KnowledgeBase, path: Path) -> tuple[list[str], list[str]]:
    return kb.registry.sync(path.read_bytes(), str(path))


def _loaded_alone(kb: KnowledgeBase, path: Path) -> dict[str, set[str]]:
    """The store with ``path`` loaded (and nothing else of the lab's), then put back as it was."""
    kb.load([path])
    expected = triples_by_graph(kb)
    for name in ("A", "B"):
        kb.registry.deregister(LAB + name)
    return expected


def test_an_edited_owls_file_replaces_what_its_load_gave(kb: KnowledgeBase, tmp_path: Path) -> None:
    """Service A's input type changes from the file's stub lab:Widget to lab:Gadget, and the input both
    services share (``#Robot``) from a MobileRobot to a Robot: the new inputs and no second OWLS model,
    as if only the new file was loaded. The shared input goes with the second service replaced; read for
    each service alone, it stayed, with both types."""
    text = _pair("Gadget").replace("robots.owl#MobileRobot", "robots.owl#Robot")
    expected = _loaded_alone(kb, _file(tmp_path, text, "pair.owls"))
    kb.load([_file(tmp_path, _pair(), "pair.owls")])
    assert _sync(kb, _file(tmp_path, text, "pair.owls")) == ([], [LAB + "A", LAB + "B"])
    assert triples_by_graph(kb) == expected
    robots = "http://example.org/ontology/robots.owl#"
    assert sorted(p.type for p in kb.description(LAB + "A").inputs) == [
        "http://example.org/lab#Gadget",
        robots + "Robot",
    ]
    assert [p.type for p in kb.description(LAB + "B").inputs] == [robots + "Robot"]


def test_a_deregistered_service_comes_back_and_the_other_is_updated(kb: KnowledgeBase, tmp_path: Path) -> None:
    pair = _file(tmp_path, _pair(), "pair.owls")
    kb.load([pair])
    loaded = triples_by_graph(kb)
    kb.registry.deregister(LAB + "A")
    assert _sync(kb, pair) == ([LAB + "A"], [LAB + "B"])
    assert triples_by_graph(kb) == loaded
    assert _sync(kb, pair) == ([], [LAB + "A", LAB + "B"])  # the same file again changes nothing
    assert triples_by_graph(kb) == loaded


def test_an_owls_file_never_loaded_is_registered_as_a_load_would(kb: KnowledgeBase, tmp_path: Path) -> None:
    pair = _file(tmp_path, _pair(), "pair.owls")
    expected = _loaded_alone(kb, pair)
    assert _sync(kb, pair) == ([LAB + "A", LAB + "B"], [])
    assert triples_by_graph(kb) == expected


def test_a_file_that_cannot_be_converted_leaves_the_store_as_it_was(kb: KnowledgeBase, tmp_path: Path) -> None:
    pair = _file(tmp_path, _pair(), "pair.owls")
    kb.load([pair])
    kb.registry.deregister(LAB + "A")
    partial = triples_by_graph(kb)
    truncated = _file(tmp_path, _pair("Gadget")[:-200], "pair.owls")
    with pytest.raises(RdfParseError, match=r"pair\.owls"):
        _sync(kb, truncated)
    assert triples_by_graph(kb) == partial
    # a service with neither a profile nor a process: the loader's refusal, before anything is written
    head = _pair()[: _pair().index("<owl:Ontology")]
    hollow = head + '<service:Service rdf:ID="A"/>\n</rdf:RDF>\n'
    with pytest.raises(RdfParseError, match="neither a profile nor a process"):
        _sync(kb, _file(tmp_path, hollow, "pair.owls"))
    assert triples_by_graph(kb) == partial
    assert not kb.registry.is_registered(LAB + "A") and kb.registry.is_registered(LAB + "B")


def test_a_device_by_a_service_s_iri_is_refused(kb: KnowledgeBase, tmp_path: Path) -> None:
    device = _file(
        tmp_path, f'<{LAB}A> a <https://w3id.org/cbrs/core#Device> ; <http://www.w3.org/2000/01/rdf-schema#label> "x" .'
    )
    kb.load([device])
    held = triples_by_graph(kb)
    with pytest.raises(AlreadyRegisteredError, match=f"{LAB}A"):
        _sync(kb, _file(tmp_path, _pair(), "pair.owls"))
    assert triples_by_graph(kb) == held


def test_register_without_update_names_the_one_command(kb: KnowledgeBase, tmp_path: Path) -> None:
    pair = _file(tmp_path, _pair(), "pair.owls")
    kb.load([pair])
    kb.registry.deregister(LAB + "A")
    partial = triples_by_graph(kb)
    for attempt in (kb.registry.update, kb.registry.register):
        with pytest.raises(InvalidDescriptionError) as caught:
            attempt(pair.read_bytes(), str(pair))
        assert str(caught.value).endswith(
            f"1 of its services is loaded already ({LAB}B): cbrs register --update {pair} replaces it and "
            "registers the others, in one transaction"
        )
    assert triples_by_graph(kb) == partial


def test_the_command(tmp_path: Path) -> None:
    """On a store directory of its own: what it prints, and the store as one load of the file leaves it."""
    location = str(tmp_path / "store")
    pair = _file(tmp_path, _pair(), "pair.owls")
    assert run("load", str(OWLS / "ontology"), store=location)[0] == 0
    assert run("load", str(pair), store=location)[0] == 0
    count = "SELECT (COUNT(*) AS ?n) WHERE { GRAPH ?g { ?s ?p ?o } }"
    loaded = run("query", count, store=location)
    assert run("deregister", LAB + "A", store=location)[0] == 0
    code, said = run("register", "--update", str(pair), store=location)
    lines = said.splitlines()
    assert code == 0 and lines[:2] == ["registered pair:A", "updated pair:B"]  # the browser's derived names
    # and the notes a load of the file prints (its made-up classes, its service without a process)
    assert "unresolved parameter types (declared by no loaded ontology): 2" in lines[2]
    assert any(line.startswith("conversion notes: ") and "has no process" in line for line in lines[3:])
    assert run("query", count, store=location) == loaded
