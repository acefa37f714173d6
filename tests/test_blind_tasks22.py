"""The twenty-second blind round (docs/tasks.md, "A twenty-second round"): what its tasks found, checked by the
checks before a run (no step runs) or by the store's update alone."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import pytest

from cbrs.actions.composer import Composer
from cbrs.actions.plan import Plan
from cbrs.actions.runner import run_task
from cbrs.kb import KnowledgeBase
from cbrs.kb.graph_slips import GraphSlipError
from cbrs.kb.model import Requirement
from cbrs.kb.namespaces import GraphName
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim.components import SimEnvironment
from cbrs.sim.place_spots import resting_surface
from cbrs.sim.run_checks import PlaceCrowdedError, PlaceFloatsError
from cbrs.sim.world import open_world

EXAMPLES = Path(__file__).parent.parent / "docs" / "examples"
LAB22 = "https://example.org/lab22#"


class _Checked(Exception):
    """Raised once the checks before a run have passed: the test needs no step to run."""


class _CheckOnly(SimEnvironment):
    def given(self, plan: Plan, requirements: Mapping[str, Requirement]) -> dict[str, Any]:
        super().given(plan, requirements)  # designates the inputs and runs the checks before a run
        raise _Checked(plan.task)


def _store(*steps: tuple[str, str]) -> KnowledgeBase:
    kb = KnowledgeBase.open(":memory:")
    for graph, name in steps:
        if graph == "update":
            kb.update((EXAMPLES / name).read_text())
        else:
            kb.load([EXAMPLES / name], graph=graph)
    return kb


def test_an_update_into_a_misspelt_cbrs_graph_is_refused_and_changes_nothing() -> None:
    """lab22_mistake_pen_drawer_graph.ru declares its own PREFIX graph: with a hash (graph#map); it was
    accepted, "https://w3id.org/cbrs/graph#map: 9 added", and no task saw the drawer. It is refused, naming
    the graph meant; a lab's graph of its own is still written."""
    kb = KnowledgeBase.open(":memory:")
    before = len(list(kb.store.quads()))
    with pytest.raises(GraphSlipError) as refused:
        kb.update((EXAMPLES / "lab22_mistake_pen_drawer_graph.ru").read_text())
    assert len(list(kb.store.quads())) == before
    error = refused.value
    assert error.meant in (GraphName.MAP, GraphName.ONTOLOGY)
    assert error.graph == "https://w3id.org/cbrs/graph#" + error.meant.value
    assert f"did you mean graph:{error.meant.value}" in str(error) and "nothing was changed" in str(error)
    kb.update(
        "INSERT DATA { GRAPH <http://example.org/lab22/notes> { <http://example.org/a> <http://example.org/b> 1 } }"
    )
    assert len(list(kb.store.quads())) > before


def test_a_region_whose_floor_is_above_the_table_is_refused_before_anything_moves() -> None:
    """PenIntoTheDrawer: the drawer's bottom (home:minZ 0.76) is 1 cm above the table it stands on. The pen
    was set down on the table within the drawer's floor plan, "did not come to rest in PenDrawer1", the
    belief took it for in, and the run failed after a re-plan (8.4 s). It is refused before the run, the
    region and the table named; with home:minZ 0.75 the drawer rests on the table's top."""
    kb = _store(("update", "lab22_pen_drawer.ru"), ("requirements", "lab22_pen_into_the_drawer.ttl"))
    smap = SemanticMap.read(kb)
    support, top = resting_surface(smap, smap.things[LAB22 + "PenDrawer1"])
    assert support is not None and support.iri.endswith("#KitchenTable") and top == pytest.approx(0.75)
    with open_world(seed=0, semantic_map=smap) as world:
        started = world.time
        with pytest.raises(PlaceFloatsError) as refused:
            run_task(kb, "PenIntoTheDrawer", _CheckOnly(world, kb), composer=Composer(kb))
        assert world.time == started
    error = refused.value
    assert error.place == LAB22 + "PenDrawer1" and error.bottom == pytest.approx(0.76)
    assert "1.0 cm above the top of the KitchenTable" in str(error) and "home:minZ 0.75" in str(error)


def test_a_thing_the_plan_moves_first_leaves_room_where_it_stood() -> None:
    """MakeRoomForThePen: the cup to a free spot, then the pen to the cup's spot. The plan moves the cup
    first, and the check refused the pen's spot as crowded by the cup where it stood at the start. It now
    passes; a swap, where neither can go first, is refused saying a third place is needed."""
    kb = _store(
        ("ontology", "lab22_two_spots.ttl"),
        ("map", "lab22_two_spots.ttl"),
        ("ontology", "lab22_free_spot.ttl"),
        ("map", "lab22_free_spot.ttl"),
        ("requirements", "lab22_make_room.ttl"),
        ("requirements", "lab22_swap_cup_and_pen.ttl"),
    )
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        with pytest.raises(_Checked):
            run_task(kb, "MakeRoomForThePen", _CheckOnly(world, kb), composer=Composer(kb))
        with pytest.raises(PlaceCrowdedError) as refused:
            run_task(kb, "SwapCupAndPen", _CheckOnly(world, kb), composer=Composer(kb))
    error = refused.value
    assert [iri.rsplit("#", 1)[1] for iri, _, _ in error.blockers] in (["Pen"], ["Cup"])
    assert "but only after" in str(error) and "a third place" in str(error)
