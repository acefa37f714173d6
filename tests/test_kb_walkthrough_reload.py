"""A lab edits its description file and loads it again with cbrs load. A load adds, and the blank nodes
of a changed file get other names, so the description would gain a second OWLS model and a second QoS
model (both shown, both matched). The load is refused instead, naming the file and what to do; the same
file loaded again still adds nothing."""

from __future__ import annotations

from pathlib import Path

import pytest

from cbrs.kb import InvalidDescriptionError, KnowledgeBase

pytestmark = pytest.mark.both_stores

HEAD = """@prefix cbrs: <https://w3id.org/cbrs/core#> .
@prefix ex: <http://example.org/mini#> .
"""
CAMERA = """ex:Cam a cbrs:DynamicPerceptionComponent ; cbrs:deviceName "LabCam" ; cbrs:serviceName "Detect" ;
    cbrs:hasOWLSModel [ cbrs:hasOutput [ cbrs:parameterType ex:Location ] ] ;
    cbrs:hasQoSModel [ cbrs:responseTime {time} ] .
"""
NEED = """ex:Need a cbrs:Requirement ; cbrs:deviceName "Robot" ; cbrs:serviceName "Need" ;
    cbrs:hasOWLSModel [ cbrs:hasOutput [ cbrs:parameterType ex:Location ] ] ;
    cbrs:hasQoSModel [ cbrs:responseTime {time} ] .
"""


@pytest.mark.parametrize(("text", "graph"), [(CAMERA, None), (NEED, "requirements")])
def test_a_changed_file_loaded_again_is_refused(mini_kb: KnowledgeBase, tmp_path: Path, text: str, graph: str) -> None:
    path = tmp_path / "lab.ttl"
    path.write_text(HEAD + text.format(time="0.2"), encoding="utf-8")
    mini_kb.load([path], graph=graph)
    before = mini_kb.store.dump()
    mini_kb.load([path], graph=graph)  # the same file: nothing new
    assert mini_kb.store.dump() == before
    path.write_text(HEAD + text.format(time="0.3"), encoding="utf-8")
    with pytest.raises(InvalidDescriptionError) as caught:
        mini_kb.load([path], graph=graph)
    message = str(caught.value)
    assert message.startswith(f"{path}:3: <http://example.org/mini#")
    assert "a description has one OWLS model" in message
    assert "is in the store already and a load adds to it" in message and "register --update" in message
    assert mini_kb.store.dump() == before


def test_a_description_the_store_does_not_hold_loads(mini_kb: KnowledgeBase, tmp_path: Path) -> None:
    path = tmp_path / "lab.ttl"
    path.write_text(HEAD + CAMERA.format(time="0.2"), encoding="utf-8")
    mini_kb.load([path])
    assert [q.value for q in mini_kb.description("http://example.org/mini#Cam").qos] == [0.2]


def test_the_same_file_with_non_canonical_numbers_loads_again(mini_kb: KnowledgeBase, tmp_path: Path) -> None:
    """The store keeps "0.50"^^xsd:decimal as "0.5": read back beside the file's spelling, one value must
    not count as two (a reload of the bundled services.ttl into a seeded store was refused so)."""
    path = tmp_path / "lab.ttl"
    sea = "cbrs:hasSEAModel [ cbrs:minX 0.0 ; cbrs:maxX 10.00 ; cbrs:minY 0.0 ; cbrs:maxY 5.0 ] ;"
    path.write_text(
        HEAD + CAMERA.format(time="0.50").replace("cbrs:hasQoSModel", sea + " cbrs:hasQoSModel"), encoding="utf-8"
    )
    mini_kb.load([path])
    before = mini_kb.store.dump()
    mini_kb.load([path])
    assert mini_kb.store.dump() == before


def test_the_bundled_services_load_again_into_a_seeded_store() -> None:
    from cbrs.kb.resources import ontology_dir

    kb = KnowledgeBase.open(":memory:")
    before = kb.store.dump()
    kb.load([ontology_dir() / "services.ttl", ontology_dir() / "requirements.ttl"])
    assert kb.store.dump() == before


def test_an_edited_requirement_is_deregistered_then_loaded_again(mini_kb: KnowledgeBase, tmp_path: Path) -> None:
    """Requirements have no registry of their own; deregister removes one from the requirements graph,
    so the way the refusal names (remove it, load again) works for them too."""
    path = tmp_path / "need.ttl"
    path.write_text(HEAD + NEED.format(time="0.2"), encoding="utf-8")
    before = mini_kb.store.dump()
    mini_kb.load([path], graph="requirements")
    path.write_text(HEAD + NEED.format(time="0.3"), encoding="utf-8")
    with pytest.raises(InvalidDescriptionError, match="cbrs deregister IRI, which removes a requirement too"):
        mini_kb.load([path], graph="requirements")
    assert mini_kb.registry.deregister("http://example.org/mini#Need") == 8
    assert mini_kb.store.dump() == before
    mini_kb.load([path], graph="requirements")
    assert [q.value for q in mini_kb.description("http://example.org/mini#Need").qos] == [0.3]
