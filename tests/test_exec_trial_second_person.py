"""A second person loaded into the map (new-user trial: a task for a new receiving person). The map read,
but the simulation built one person, so every later run was refused, also those that never look for a
person ("the simulated home takes one mobile robot and one person"). The home now holds both; a task whose
input is of class home:Person cannot tell which one it means when both are stated to be a home:Person
(one stated only of a narrower class, home:ElderlyPerson, is not what home:Person designates: docs/tasks.md)
and is refused by name before anything moves (tests/test_home_people.py runs a task for one of two people)."""

from __future__ import annotations

from pathlib import Path

import pytest

from cbrs.actions.composer import Composer
from cbrs.actions.runner import run_task
from cbrs.kb import KnowledgeBase
from cbrs.kb.semantic_map import AmbiguousDesignatorError, SemanticMap
from cbrs.sim.components import SimEnvironment
from cbrs.sim.world import open_world

GRANDMA = """@prefix home: <https://w3id.org/cbrs/home#> . @prefix world: <https://w3id.org/cbrs/world#> .
@prefix lab: <https://example.org/lab#> .
lab:Grandma a home:Person ; home:colourName "red" ; home:rgba "0.85 0.1 0.1 1" ;
    home:isLocated world:Bedroom ; home:x 4.0 ; home:y 7.0 ; home:yaw 0.0 .
"""


def test_a_second_person_is_built_and_a_task_for_a_person_asks_which(tmp_path: Path) -> None:
    kb = KnowledgeBase.open(":memory:")
    (tmp_path / "grandma.ttl").write_text(GRANDMA, encoding="utf-8")
    kb.load([tmp_path / "grandma.ttl"], graph="map")
    with open_world(0, semantic_map=SemanticMap.read(kb)) as world:
        assert sorted(world.people) == ["Grandma", "Person"] and {"Grandma", "Person"} <= set(world.bodies)
        started, base = world.time, world.base_pose()
        with pytest.raises(AmbiguousDesignatorError) as refused:
            run_task(kb, "FetchMyPen", SimEnvironment(world, kb), composer=Composer(kb))
        assert world.time == started and world.base_pose() == base  # nothing moved
    assert refused.value.candidates == ["https://example.org/lab#Grandma", "https://w3id.org/cbrs/world#Person"]
    assert "give the one the task means a class of its own" in str(refused.value)
