"""``cbrs register FILE`` refuses an advertisement another graph holds, as ``cbrs register --update``
does. ``cbrs load`` puts a file that declares classes into graph:ontology, descriptions and all; before,
registering a description by the same IRI wrote a second one into graph:services, and every reader
took the two as one: two inputs and two outputs where the file gives one each, four QoS values.
Now the refusal names the IRI and the graph it is in, and nothing is written."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from cbrs.kb import KnowledgeBase
from cbrs.kb.errors import OutsideRegistryError
from cbrs.kb.namespaces import OWL, GraphName

from .conftest import MINI_FILES, make_mini_kb, ontology_dir
from .test_cli import run
from .test_deregister_owls import triples_by_graph
from .test_register_update_partial import EX, TWO, _file

pytestmark = pytest.mark.both_stores

# TWO's advertisements as TrackC and TrackD, in a file that also declares a class: cbrs load sends it to graph:ontology
LAB = (
    f"@prefix owl: <{OWL}> .\n"
    + TWO.replace("TrackA", "TrackC").replace("TrackB", "TrackD")
    + "ex:Widget a owl:Class .\n"
)


@pytest.fixture
def kb(store_location: str, tmp_path: Path) -> Iterator[KnowledgeBase]:
    kb = make_mini_kb(store_location)
    kb.load([Path(__file__).parent / "data" / "owls" / "ontology"])
    kb.load([_file(tmp_path, LAB, "lab.ttl")])
    yield kb
    kb.close()


def test_registering_an_advertisement_another_graph_holds_is_refused(kb: KnowledgeBase, tmp_path: Path) -> None:
    loaded = triples_by_graph(kb)
    path = _file(tmp_path, TWO.replace("TrackA", "TrackC"), "c.ttl")  # TrackC, held in graph:ontology, and TrackB
    with pytest.raises(OutsideRegistryError) as caught:
        kb.registry.register(path.read_bytes(), str(path))
    assert caught.value.iri == EX + "TrackC"
    assert caught.value.graph == GraphName.ONTOLOGY.iri
    assert f"<{EX}TrackC> is in the graph <{GraphName.ONTOLOGY.iri}>" in str(caught.value)
    assert triples_by_graph(kb) == loaded  # TrackB, new, was not registered either: all or nothing
    description = kb.description(EX + "TrackC")
    assert (len(description.inputs), len(description.outputs), len(description.qos)) == (1, 1, 1)


def test_an_advertisement_of_its_own_is_registered_as_before(kb: KnowledgeBase, tmp_path: Path) -> None:
    path = _file(tmp_path, TWO, "two.ttl")
    assert kb.registry.register(path.read_bytes(), str(path)) == [EX + "TrackA", EX + "TrackB"]


def test_the_command_names_the_iri_and_the_graph(tmp_path: Path) -> None:
    """On a store directory of its own: the command's refusal, and no --update advice (which refuses it too)."""
    location = str(tmp_path / "store")
    assert run("load", str(ontology_dir() / "core.ttl"), *map(str, MINI_FILES), store=location)[0] == 0
    assert run("load", str(_file(tmp_path, LAB, "lab.ttl")), store=location)[0] == 0
    path = _file(tmp_path, TWO.replace("TrackA", "TrackC"), "c.ttl")
    code, out = run("register", str(path), store=location)
    assert code == 1
    assert f"<{EX}TrackC> is in the graph <{GraphName.ONTOLOGY.iri}>, not in graph:services" in out
    assert "--update" not in out
