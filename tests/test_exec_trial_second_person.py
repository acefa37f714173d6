"""A second person loaded into the map (new-user trial: a task for a new receiving person). The map
reads, but the simulation builds one person, so every later run failed with only the counts ("has 1 and
2"); the refusal now names them and says that it stops whatever task runs, and how to take one out."""

from __future__ import annotations

from pathlib import Path

import pytest

from cbrs.kb import KnowledgeBase
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim.world import open_world

GRANDMA = """@prefix home: <https://w3id.org/cbrs/home#> . @prefix world: <https://w3id.org/cbrs/world#> .
@prefix lab: <https://example.org/lab#> .
lab:Grandma a home:ElderlyPerson ; home:colourName "red" ; home:rgba "0.85 0.1 0.1 1" ;
    home:isLocated world:Bedroom ; home:x 4.0 ; home:y 7.0 ; home:yaw 0.0 .
"""


def test_a_second_person_is_refused_by_name_before_the_home_is_built(tmp_path: Path) -> None:
    kb = KnowledgeBase.open(":memory:")
    (tmp_path / "grandma.ttl").write_text(GRANDMA, encoding="utf-8")
    kb.load([tmp_path / "grandma.ttl"], graph="map")
    with (
        pytest.raises(ValueError, match="one mobile robot and one person") as refused,
        open_world(0, semantic_map=SemanticMap.read(kb)),
    ):
        pass
    message = str(refused.value)
    assert "people: https://example.org/lab#Grandma, https://w3id.org/cbrs/world#Person" in message
    assert "take the extra ones out of graph:map" in message and "whatever task runs" in message
