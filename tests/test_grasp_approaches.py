"""Several grasp approaches per class, best first (``home:graspApproach "side top"``): the map reads the
list, each arm holds an object by the first approach that works for its own hold (from where it takes
it to where it lets it go), and each choice says why the approaches before it were passed over.

The bundled cup allows ``"side top"`` (``home:Drinkware``); the tests here that need another list give
``home:Cup`` (nearer the cup than ``home:Drinkware``, so it overrides it) the list they need, in the
ontology graph, as a map author would. The bundled list at work, the cup passed by its side grasp and
loaded by its top grasp and the cup carried to a tray by the side grasp both arms hold all the way, is
tests/test_turtle_tasks_arms.py's runs.
"""

from __future__ import annotations

import re
from pathlib import Path
from types import SimpleNamespace
from typing import cast

import pytest

from cbrs.actions.composer import Composer
from cbrs.actions.runner import run_task
from cbrs.kb import KnowledgeBase
from cbrs.kb.hands import PANDA_HAND
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import GRASP_APPROACHES, MapError, SemanticMap
from cbrs.sim import skills
from cbrs.sim.arms import ArmSide
from cbrs.sim.components import CannotLoadError, SimContext, SimEnvironment
from cbrs.sim.grasping import GraspKind, ObjectModel
from cbrs.sim.grounding import manipulation_of
from cbrs.sim.values import GraspPlan, Manipulation, to_json
from cbrs.sim.world import open_world
from tests.test_turtle_tasks_arms import FETCH_MY_CUP, knowledge

HOME, WORLD = PREFIXES["home"], PREFIXES["world"]


def cup_grasps(approaches: str) -> str:
    return (
        "@prefix home: <https://w3id.org/cbrs/home#> .\n"
        f'home:Cup home:graspApproach "{approaches}" ; home:graspHeightRatio 0.7 .\n'
    )


def world_facts(kb: KnowledgeBase) -> set[tuple[str, str, str]]:
    return {(r["thing"].value, r["relation"].value, r["other"].value) for r in kb.select("world_facts")}


# -- reading the list --------------------------------------------------------------------------------


def test_a_class_gives_its_approaches_best_first_and_the_nearest_class_that_says_wins(tmp_path: Path) -> None:
    smap = SemanticMap.read(knowledge(tmp_path, ("ontology", cup_grasps("side top"))))
    cup, pen = smap.objects[WORLD + "Cup"], smap.objects[WORLD + "Pen"]
    assert cup.grasp_approaches == ("side", "top") and cup.grasp_approach == "side"
    assert cup.grasp_height == pytest.approx(0.07)
    assert pen.grasp_approaches == ("top",)  # home:WritingInstrument's, untouched
    model = ObjectModel.of(cup)
    assert model.grasp is GraspKind.SIDE and model.preference == (GraspKind.SIDE, GraspKind.TOP)
    assert model.by(GraspKind.TOP).grasp is GraspKind.TOP and model.by(GraspKind.TOP).preference == model.preference
    assert ObjectModel.of(pen).approaches == ()  # one approach: nothing to choose, as before
    narrowed = SemanticMap.read(knowledge(tmp_path, ("ontology", cup_grasps("top"))))
    assert narrowed.objects[WORLD + "Cup"].grasp_approaches == ("top",)  # the whole list is overridden


def test_two_approach_statements_give_no_order_and_are_refused_naming_both() -> None:
    kb = KnowledgeBase.open(":memory:")
    kb.update(
        f"INSERT DATA {{ GRAPH graph:ontology {{ <{HOME}Cup> <{HOME}graspApproach> 'side' , 'top' ; "
        f"<{HOME}graspHeightRatio> 0.7 }} }}"
    )
    with pytest.raises(MapError, match="'side' and 'top'") as refused:
        SemanticMap.read(kb)
    assert refused.value.thing == HOME + "Cup"
    assert '"side top"' in str(refused.value)  # how to write it instead


@pytest.mark.parametrize("approaches", ["side side", "diagonal", "side sideways", " "])
def test_an_unknown_or_repeated_approach_is_refused_when_the_map_is_read(tmp_path: Path, approaches: str) -> None:
    kb = knowledge(tmp_path, ("ontology", cup_grasps(approaches)))
    with pytest.raises(MapError, match="graspApproach") as refused:
        SemanticMap.read(kb)
    assert refused.value.thing == HOME + "Cup"
    assert "'top', 'side'" in str(refused.value)


def test_the_map_accepts_exactly_the_approaches_the_grasp_planner_computes() -> None:
    assert set(GRASP_APPROACHES) == {kind.value for kind in GraspKind}


def test_a_grasp_value_keeps_its_own_approach_first_and_gets_the_classes_others_after_it(tmp_path: Path) -> None:
    """A value between components names one approach (its JSON has one field for it): the map adds the
    class's others after it, so a grasp computed elsewhere is tried first and not lost."""
    smap = SemanticMap.read(knowledge(tmp_path, ("ontology", cup_grasps("side top"))))
    ctx = cast(SimContext, SimpleNamespace(map=smap))
    cup = ObjectModel.of(smap.objects[WORLD + "Cup"])
    given_top = to_json(GraspPlan(WORLD + "Cup", cup.by(GraspKind.TOP)), HOME + "GraspPose")
    assert manipulation_of(ctx, given_top).model.preference == (GraspKind.TOP, GraspKind.SIDE)
    given_side = to_json(Manipulation(WORLD + "Cup", cup), HOME + "ManipulationProperty")
    assert manipulation_of(ctx, given_side).model.preference == (GraspKind.SIDE, GraspKind.TOP)
    pen = ObjectModel.of(smap.objects[WORLD + "Pen"])
    assert manipulation_of(ctx, to_json(GraspPlan(WORLD + "Pen", pen), HOME + "GraspPose")).model.approaches == ()


def test_a_top_grasp_deeper_below_the_top_than_the_palm_is_ruled_out() -> None:
    cup = ObjectModel("Cup", "red", 0.10, 0.06, GraspKind.TOP, 0.07)
    assert skills.can_grip(cup, PANDA_HAND) == ""  # 3.0 cm below its top, the palm 3.4 cm above the grasp point
    assert cup.top_clearance(PANDA_HAND) == pytest.approx(PANDA_HAND.palm_depth - 0.03)
    glass = ObjectModel("Glass", "cyan", 0.16, 0.06, GraspKind.TOP, 0.08)
    assert "8.0 cm below its top" in skills.can_grip(glass, PANDA_HAND)
    assert skills.can_grip(glass.by(GraspKind.SIDE), PANDA_HAND) == ""  # a side grasp has no palm above the object


# -- choosing, and acting on the choice --------------------------------------------------------------


def test_a_cup_allowed_only_its_side_grasp_is_still_refused_before_anything_moves(tmp_path: Path) -> None:
    kb = knowledge(tmp_path, ("ontology", cup_grasps("side")), ("requirements", FETCH_MY_CUP))
    before = set(kb.store.quads())
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        cup, base = world.pose("Cup").position, world.base_pose()
        with pytest.raises(CannotLoadError) as refused:
            run_task(kb, "FetchMyCup", SimEnvironment(world, kb), composer=Composer(kb))
        assert world.pose("Cup").position[:2] == pytest.approx(cup[:2], abs=0.005)
        assert world.base_pose().distance_to(base.x, base.y) < 0.01
    assert refused.value.thing == WORLD + "Cup"
    assert "only the left arm reaches the Cup and only the right arm the platform" in str(refused.value)
    assert "cannot hold the Cup by its side grasp over the platform" in str(refused.value)
    assert "by its top grasp" not in str(refused.value)  # no arm asked to take it so
    assert str(refused.value).endswith(  # the approach that would serve, as advice (the eleventh round's coaster)
        'allowed its top grasp too, an arm would load it: give its class home:graspApproach "side top" (the '
        "approaches it may be taken by, best first)"
    )
    assert set(kb.store.quads()) == before


def test_a_cup_no_approach_can_load_is_refused_naming_each_approach(tmp_path: Path) -> None:
    """A tall glass: the side grasp cannot be held over the platform, and a top grasp would press the
    palm on its top. The refusal says both, before anything moves."""
    kb = knowledge(tmp_path, ("ontology", cup_grasps("side top")), ("requirements", FETCH_MY_CUP))
    kb.update(
        "DELETE { GRAPH graph:map { world:Cup home:sizeZ ?z } } "
        "INSERT { GRAPH graph:map { world:Cup home:sizeZ 0.16 } } "
        "WHERE { GRAPH graph:map { world:Cup home:sizeZ ?z } }"
    )
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world, pytest.raises(CannotLoadError) as refused:
        run_task(kb, "FetchMyCup", SimEnvironment(world, kb), composer=Composer(kb))
    message = str(refused.value)
    assert "cannot hold the Cup by its side grasp over the platform" in message
    assert "a top grasp would hold the Cup 4.8 cm below its top" in message


def test_a_cup_no_one_approach_serves_all_the_way_is_set_down_and_taken_anew(tmp_path: Path) -> None:
    """At (8.02, 3.38) only the right arm reaches the cup, at the edge of its reach, where its hand holds
    the side grasp but not the top one; over the platform it holds the top grasp, not the side one. It
    takes the cup by its side grasp, sets it down nearer, takes it anew from the top and loads it."""
    kb = knowledge(tmp_path, ("ontology", cup_grasps("side top")), ("requirements", FETCH_MY_CUP))
    kb.update(
        "DELETE { GRAPH graph:map { world:Cup home:x ?x ; home:y ?y } } "
        "INSERT { GRAPH graph:map { world:Cup home:x 8.02 ; home:y 3.38 } } "
        "WHERE { GRAPH graph:map { world:Cup home:x ?x ; home:y ?y } }"
    )
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        environment = SimEnvironment(world, kb)
        result = run_task(kb, "FetchMyCup", environment, composer=Composer(kb))
        choices = environment.context.choices
    assert result.succeeded, result.report.reason if result.report else result.composition.unsatisfied
    assert not result.replans
    assert (WORLD + "Cup", HOME + "isWith", WORLD + "Person") in world_facts(kb)
    right = ArmSide.RIGHT
    assert [(c.arm, c.model.grasp) for c in choices] == [(right, GraspKind.SIDE), (right, GraspKind.TOP)]
    first = str(choices[0])  # where the Kinect saw it (the seed moves it by up to 2 cm)
    assert first.startswith("setting the Cup down to take it anew")
    assert re.search(r"the right arm cannot hold the Cup by its top grasp at \(8\.0\d, 3\.[34]\d\)", first)
    assert "cannot hold the Cup by its side grasp over the platform" in first
