"""Composition honours the service effective area (SEA): a step's component must cover where the task's
things it handles are (docs/composition.md#where-a-step-must-be-effective).

The bundled FetchMyPen recognises the pen with the Kinect over the kitchen table. Two extra recognisers
offer the same service: one on the bedroom's ceiling camera, one on the kitchen's
(tests/data/composition_area). A re-plan after the Kinect failed composes without it, as the runner
does (``actions.runner``: the same advertisements, less the avoided components, from the belief).
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import pytest

from cbrs.actions.areas import AreaRule, Whereabouts, WorldPlaces
from cbrs.actions.belief import BeliefState, Observation
from cbrs.actions.composer import ComposeConfig, Composer, CompositionResult, PlanStatus
from cbrs.actions.graph import parameter_names
from cbrs.kb import Advertisement, EffectiveArea, KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.reasoner.sea import overlap, reaches, uncovered
from cbrs.reasoner.taxonomy import TaxonomyIndex

DATA = Path(__file__).parent / "data" / "composition_area"
SVC = PREFIXES["svc"]
HOME = PREFIXES["home"]
KINECT = SVC + "RecogniseObjectByColour_Kinect01"
BEDROOM = SVC + "RecogniseObjectByColour_CeilingCamera03"
KITCHEN = SVC + "RecogniseObjectByColour_CeilingCamera02"
KINECT_DEVICE = SVC + "Kinect01"


def _kb(*files: str) -> KnowledgeBase:
    kb = KnowledgeBase.open(":memory:")
    kb.load([DATA / file for file in files])
    return kb


@pytest.fixture(scope="module")
def bedroom_kb() -> Iterator[KnowledgeBase]:
    kb = _kb("bedroom_recogniser.ttl")
    yield kb
    kb.close()


@pytest.fixture(scope="module")
def two_recognisers_kb() -> Iterator[KnowledgeBase]:
    kb = _kb("bedroom_recogniser.ttl", "kitchen_recogniser.ttl")
    yield kb
    kb.close()


def _without(kb: KnowledgeBase, failed: str, config: ComposeConfig | None = None) -> CompositionResult:
    """The re-plan's composition once ``failed`` (a component, or every component of a device) is avoided."""
    kept = [ad for ad in kb.advertisements() if failed not in (ad.iri, ad.device)]
    return Composer(kb, config, advertisements=kept).compose("FetchMyPen", belief=True)


def _components(result: CompositionResult) -> list[str]:
    assert result.plan is not None, [u.text() for u in result.unsatisfied]
    return [step.component for step in result.plan.steps]


def _recogniser(result: CompositionResult) -> tuple[str, tuple[str, ...]]:
    assert result.plan is not None, [u.text() for u in result.unsatisfied]
    step = next(s for s in result.plan.steps if "RecogniseObjectByColour" in s.component)
    return step.component, step.alternatives


def _pen(kb: KnowledgeBase) -> str:
    composer = Composer(kb)
    requirement = composer.task("FetchMyPen").requirement
    world = WorldPlaces.read(kb, composer.index, belief=False)
    return world.locate(kb, composer.index, requirement, parameter_names(requirement.inputs))["pen"].thing


def test_an_out_of_area_recogniser_is_no_alternative(bedroom_kb: KnowledgeBase) -> None:
    chosen, alternatives = _recogniser(Composer(bedroom_kb).compose("FetchMyPen"))
    assert chosen == KINECT
    assert BEDROOM not in alternatives
    unchecked = Composer(bedroom_kb, ComposeConfig(respect_area=False)).compose("FetchMyPen")
    assert BEDROOM in {_recogniser(unchecked)[0], *_recogniser(unchecked)[1]}  # the types alone admit it


def test_the_replan_refuses_the_out_of_area_recogniser_and_says_why(bedroom_kb: KnowledgeBase) -> None:
    # the Kinect's recogniser failed: the re-plan finds the pen another way, not with the bedroom camera
    assert BEDROOM not in _components(_without(bedroom_kb, KINECT))
    # the Kinect itself failed: only the bedroom camera offers the pen's position, and it cannot see it
    result = _without(bedroom_kb, KINECT_DEVICE)
    assert result.status is PlanStatus.UNSOLVABLE
    [unmet] = result.unsatisfied
    assert [component for component, _ in unmet.out_of_area] == [BEDROOM]
    why = unmet.out_of_area[0][1]
    assert "does not cover" in why and "world:Pen" in why and "home:Bedroom" in why
    assert unmet.need.startswith("input objectPosition")
    assert "RecogniseObjectByColour_CeilingCamera03 was passed over" in unmet.text()
    assert result.to_dict()["unsatisfied"][0]["out_of_area"] == [{"component": BEDROOM, "why": why}]
    # without the rule, the re-plan takes the camera that cannot see the pen
    unchecked = _without(bedroom_kb, KINECT_DEVICE, ComposeConfig(respect_area=False))
    assert _recogniser(unchecked)[0] == BEDROOM


def test_a_second_in_area_recogniser_is_the_alternative_and_the_replan(two_recognisers_kb: KnowledgeBase) -> None:
    chosen, alternatives = _recogniser(Composer(two_recognisers_kb).compose("FetchMyPen"))
    assert chosen == KINECT
    assert alternatives == (KITCHEN,)
    assert _recogniser(_without(two_recognisers_kb, KINECT))[0] == KITCHEN
    assert _recogniser(_without(two_recognisers_kb, KINECT_DEVICE))[0] == KITCHEN


def test_the_belief_says_where_the_thing_is_now() -> None:
    """A re-plan composes from the belief: a pen believed in the bedroom is out of the kitchen arm's area."""
    kb = _kb("bedroom_recogniser.ttl")
    try:
        bedroom = next(ad for ad in kb.advertisements() if ad.iri == BEDROOM)
        assert bedroom.area is not None and bedroom.area.bounds is not None
        x0, x1, y0, y1 = bedroom.area.bounds
        pen = _pen(kb)
        BeliefState(kb).write(Observation({pen: HOME + "Pen"}, positions={pen: ((x0 + x1) / 2, (y0 + y1) / 2, 0.5)}))
        believed = Composer(kb).compose("FetchMyPen", belief=True)
        assert believed.status is PlanStatus.UNSOLVABLE
        text = " ".join(u.text() for u in believed.unsatisfied)
        assert "CytonDualArm01 was passed over" in text and "home:Bedroom" in text
        assert Composer(kb).compose("FetchMyPen").status is PlanStatus.PLANNED  # the map's pen: as before
    finally:
        kb.close()


def test_marker_localisation_is_not_filtered(bundled_kb: KnowledgeBase) -> None:
    """The cameras that locate the robot take its marker's colours, which the map places nowhere (and the
    robot moves between the two localisations): camera 2 stays camera 1's alternative, as before."""
    plan = Composer(bundled_kb).compose("FetchMyPen").plan
    assert plan is not None
    located = [s for s in plan.steps if s.component == SVC + "LocateMobileRobot_CeilingCamera01"]
    assert len(located) == 2
    assert all(SVC + "LocateMobileRobot_CeilingCamera02" in s.alternatives for s in located)


def _ad(iri: str, area: EffectiveArea | None) -> Advertisement:
    return Advertisement(iri, (), area=area)


def test_the_task_area_keeps_out_components_effective_only_elsewhere(bundled_kb: KnowledgeBase) -> None:
    index = TaxonomyIndex.from_kb(bundled_kb)
    bedroom = EffectiveArea((HOME + "Bedroom",), (0.0, 6.0, 5.0, 9.0))
    rule = AreaRule(index, {}, bedroom)
    kitchen = _ad("k", EffectiveArea((HOME + "Kitchen",), (6.0, 10.0, 0.0, 5.0)))
    living = _ad("l", EffectiveArea((HOME + "LivingRoom",), (0.0, 6.0, 0.0, 5.0)))  # touches along a wall
    home = _ad("h", EffectiveArea((HOME + "Home",), (0.0, 10.0, 0.0, 9.0)))
    why = rule.why_not(kitchen, ())
    assert why is not None and "lies outside the task's" in why
    assert rule.why_not(living, ()) is not None
    assert rule.why_not(home, ()) is None  # need not cover it alone: it reaches into it
    assert rule.why_not(_ad("nowhere", None), ()) is None  # no SEA model: effective everywhere
    by_boxes = AreaRule(index, {}, bedroom, boxes=True)
    assert by_boxes.why_not(living, ()) is not None and by_boxes.why_not(home, ()) is None
    assert by_boxes.why_not(_ad("boxed", EffectiveArea((HOME + "Kitchen",), (0.0, 6.0, 4.0, 6.0))), ()) is None


def test_rooms_not_boxes_unless_asked() -> None:
    """The dual arm advertises the kitchen table's box; it reaches the keys on the side table beside it
    (docs/examples/side_table.ttl). By rooms, both are in the kitchen; by boxes, the arm is passed over."""
    examples = Path(__file__).parent.parent / "docs" / "examples"
    kb = KnowledgeBase.open(":memory:")
    try:
        kb.load([examples / "side_table.ttl"], graph="map")
        kb.load([examples / "side_table_camera.ttl"])
        kb.load([examples / "fetch_my_keys.ttl"], graph="requirements")
        assert Composer(kb).compose("FetchMyKeys").status is PlanStatus.PLANNED
        boxed = Composer(kb, ComposeConfig(area_boxes=True)).compose("FetchMyKeys")
        assert boxed.status is PlanStatus.UNSOLVABLE
        passed = {component for u in boxed.unsatisfied for component, _ in u.out_of_area}
        assert any("CytonDualArm01" in component for component in passed)
    finally:
        kb.close()


def test_the_sea_rule_is_matchmakings(bundled_kb: KnowledgeBase) -> None:
    index = TaxonomyIndex.from_kb(bundled_kb)
    kitchen = EffectiveArea((HOME + "Kitchen",))
    home = EffectiveArea((HOME + "Home",))
    assert uncovered(index, kitchen, home) == []  # a room is part of the home
    assert uncovered(index, home, kitchen) == ["SEA: Home is outside Kitchen"]
    assert reaches(index, home, kitchen) and reaches(index, kitchen, home)
    assert not reaches(index, kitchen, EffectiveArea((HOME + "Bedroom",)))
    assert overlap((0, 6, 0, 5), (5, 7, 1, 2))
    assert not overlap((0, 6, 0, 5), (6, 10, 0, 5))  # rooms that share a wall
    assert overlap((0, 6, 0, 5), (6, 6, 2, 2))  # a point on the wall is in


def test_a_thing_in_the_wall_between_two_rooms_is_in_both(bundled_kb: KnowledgeBase) -> None:
    """A door in the wall between the living room and the kitchen: a kitchen door motor reaches it."""
    composer = Composer(bundled_kb)
    world = WorldPlaces.read(bundled_kb, composer.index, belief=False)
    extents = dict(world.rooms)
    kitchen, living = extents[HOME + "Kitchen"], extents[HOME + "LivingRoom"]
    assert kitchen[0] == living[1]  # the map's kitchen lies east of the living room, wall to wall
    y = (max(kitchen[2], living[2]) + min(kitchen[3], living[3])) / 2
    door = (kitchen[0] - 0.05, kitchen[0] + 0.05, y - 0.5, y + 0.5)
    rooms = world.rooms_of(door)
    assert set(rooms) == {HOME + "Kitchen", HOME + "LivingRoom"}
    rule = AreaRule(composer.index, {"door": Whereabouts("door", "door", door, rooms)}, None)
    assert rule.why_not(_ad("motor", EffectiveArea((HOME + "Kitchen",), kitchen)), {"door"}) is None
    assert rule.why_not(_ad("bedroom", EffectiveArea((HOME + "Bedroom",))), {"door"}) is not None
    by_boxes = AreaRule(composer.index, {"door": Whereabouts("door", "door", door, rooms)}, None, boxes=True)
    assert by_boxes.why_not(_ad("motor", EffectiveArea((HOME + "Kitchen",), kitchen)), {"door"}) is None
