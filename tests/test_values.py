"""Values between steps are plain JSON of the port's declared type (sim/values.py, docs/values.md), so a
component outside the process could produce or consume any of them: checked on real runs, and per type."""

from __future__ import annotations

import base64
import gc
import json
import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from cbrs.actions.components import Component, Registry, Status
from cbrs.actions.composer import Composer
from cbrs.actions.runner import RunResult, run_task
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import PREFIXES
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim.components import SimComponent, SimContext, SimEnvironment
from cbrs.sim.errors import SimulationError
from cbrs.sim.geometry import Pose2D
from cbrs.sim.grasping import GraspKind, ObjectModel
from cbrs.sim.mapping import OccupancyGrid, inflate
from cbrs.sim.perception import ObjectEstimate, PersonEstimate, RobotPoseEstimate
from cbrs.sim.planning import PlannedPath
from cbrs.sim.services import SKILLS
from cbrs.sim.values import (
    APPROACH_POSITION,
    COLOUR_FEATURE,
    DEFAULT_INFLATION_RADIUS,
    GRASP_POSE,
    MANIPULATION_PROPERTY,
    OBJECT_FEATURE,
    OBJECT_LOCATION,
    OBJECT_POSITION_3D,
    OCCUPANCY_GRID_MAP,
    PATH,
    PERSON_POSITION,
    ROBOT_LOCATION,
    ColourFeature,
    Designator,
    GraspPlan,
    MalformedValueError,
    Manipulation,
    ObjectFeature,
    check,
    concepts_of,
    decode,
    from_json,
    to_json,
)
from cbrs.sim.world import open_world

HOME, WORLD = PREFIXES["home"], PREFIXES["world"]
DOC = Path(__file__).resolve().parents[1] / "docs" / "values.md"

Invocation = tuple[str, dict[str, Any], dict[str, Any]]


class Recording(Component):
    """A component that does what another does and notes what it was given and what it gave."""

    def __init__(self, inner: Component, log: list[Invocation]) -> None:
        super().__init__(inner.iri)
        self.inner = inner
        self.log = log
        self.given: dict[str, Any] = {}

    def initialise(self, context: Any) -> None:
        self.inner.initialise(context)

    def begin(self, inputs: Mapping[str, Any]) -> None:
        self.given = dict(inputs)
        self.inner.outputs = {}
        self.inner.begin(inputs)

    def update(self) -> Status:
        status = self.inner.update()
        self.outputs, self.reason = self.inner.outputs, self.inner.reason
        if status is Status.SUCCEEDED:
            self.log.append((self.iri, self.given, dict(self.outputs)))
        return status

    def halt(self) -> None:
        self.inner.halt()

    def finalise(self) -> None:
        self.inner.finalise()


Run = tuple[RunResult, SimEnvironment, list[Invocation]]


def recorded_run(task: str) -> Run:
    kb = KnowledgeBase.open(":memory:")
    log: list[Invocation] = []
    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as world:
        environment = SimEnvironment(world, kb)
        inner = environment.registry
        registry = Registry()
        for iri in inner.names():
            registry.add(iri, lambda iri: Recording(inner(iri), log))
        environment.registry = registry
        result = run_task(kb, task, environment, composer=Composer(kb))
    return result, environment, log


@pytest.fixture(scope="module", params=["FetchMyPen", "RobotArmServeACup"])
def run(request: pytest.FixtureRequest) -> Run:
    return recorded_run(str(request.param))


def test_the_run_succeeds_with_every_effect_verified(run: Run) -> None:
    result, _, log = run
    assert result.succeeded, result.report.reason if result.report else result.composition.unsatisfied
    assert result.report is not None
    assert all(ok is True for step in result.report.steps for _, ok in step.effects)
    assert len(log) == len(result.report.steps)


def test_every_value_between_steps_is_json_of_the_declared_type(run: Run) -> None:
    result, environment, log = run
    plan = result.composition.plan
    assert plan is not None
    for step, (iri, inputs, outputs) in zip(plan.steps, log, strict=True):
        assert iri in step.candidates
        declared = dict(step.outputs)
        assert set(outputs) == set(declared), f"step {step.index} gives ports it does not advertise"
        for name, value in outputs.items():
            assert json.loads(json.dumps(value)) == value, f"step {step.index} {name}"
            assert environment.is_a(value["@type"], declared[name]), f"step {step.index} {name}: {value['@type']}"
            assert to_json(from_json(value), value["@type"]) == value  # it decodes, and back to the same JSON
        for binding in step.inputs:
            value = inputs[binding.name]
            assert json.loads(json.dumps(value)) == value, f"step {step.index} {binding.name}"
            assert binding.concept is not None
            assert environment.is_a(value["@type"], binding.concept), f"step {step.index} {binding.name}"


def test_what_passes_between_steps_is_the_same_value_the_producer_gave(run: Run) -> None:
    result, _, log = run
    plan = result.composition.plan
    assert plan is not None
    for step, (_, inputs, _) in zip(plan.steps, log, strict=True):
        for binding in step.inputs:
            if binding.source.step is not None:
                assert inputs[binding.name] == log[binding.source.step - 1][2][binding.source.name]


# -- per type ---------------------------------------------------------------------------------------


def small_grid() -> OccupancyGrid:
    """13 x 7 cells (not a multiple of 8: the packed bitmap has padding), a wall across the middle."""
    occupied = np.zeros((7, 13), dtype=bool)
    occupied[3, 2:11] = True
    occupied[0, 0] = occupied[6, 12] = True
    resolution, radius = 0.5, 0.3
    return OccupancyGrid(resolution, (-1.0, 2.0), occupied, inflate(occupied, (radius + 0.25) / 0.5), radius)


PEN = ObjectModel("Pen", "blue", 0.016, 0.016, GraspKind.TOP, 0.008)
CUP = ObjectModel("Cup", "red", 0.10, 0.06, GraspKind.SIDE, 0.06)

SAMPLES: list[tuple[Any, str]] = [
    (RobotPoseEstimate(3.01, 1.49, -0.12, "CeilingCamera01", 12.5, 48), ROBOT_LOCATION),
    (PersonEstimate(2.05, 3.61, "CeilingCamera02", 80.25, 312), PERSON_POSITION),
    (Pose2D(8.5, 2.2, math.pi / 2), APPROACH_POSITION),
    (Pose2D(8.5, 2.2, 0.0), OBJECT_LOCATION),
    (ObjectEstimate(8.07, 3.3, 0.758, 0.1, (0.14, 0.016, 0.016), "blue", "Kinect01", 40.0, 120), OBJECT_POSITION_3D),
    (ObjectEstimate(7.45, 3.32, 0.8, None, (0.06, 0.05, 0.1), "red", "Kinect01", 1.5, 300), OBJECT_POSITION_3D),
    (small_grid(), OCCUPANCY_GRID_MAP),
    (PlannedPath("astar", (0.25, 0.5), (4.0, 3.5), ((0.25, 0.5), (1.0, 1.0), (4.0, 3.5)), 4.6, 75), PATH),
    (Manipulation(WORLD + "Pen", PEN), MANIPULATION_PROPERTY),
    (GraspPlan(WORLD + "Cup", CUP), GRASP_POSE),
    (ColourFeature("blue"), COLOUR_FEATURE),
    (ObjectFeature("red"), OBJECT_FEATURE),
    (Designator(WORLD + "KitchenTable", HOME + "ObjectPlace"), HOME + "ObjectPlace"),
]


def same(a: Any, b: Any) -> bool:
    if isinstance(a, OccupancyGrid) and isinstance(b, OccupancyGrid):
        return (
            (a.resolution, a.origin, a.inflation_radius) == (b.resolution, b.origin, b.inflation_radius)
            and np.array_equal(a.occupied, b.occupied)
            and np.array_equal(a.inflated, b.inflated)
        )
    return bool(a == b)


@pytest.mark.parametrize(
    ("value", "concept"), SAMPLES, ids=lambda v: type(v).__name__ if not isinstance(v, str) else ""
)
def test_each_type_round_trips_through_json_text(value: Any, concept: str) -> None:
    data = to_json(value, concept)
    assert data["@type"] == concept
    text = json.dumps(data, allow_nan=False)
    assert json.loads(text) == data
    back = from_json(json.loads(text))
    assert type(back) is type(value) and same(back, value)
    assert to_json(back, concept) == data


def test_the_grid_is_a_packed_bitmap_row_by_row_from_the_origin() -> None:
    grid = small_grid()
    data = to_json(grid)
    assert (data["width"], data["height"], data["origin"], data["resolution"]) == (13, 7, [-1.0, 2.0], 0.5)
    packed = base64.b64decode(data["cells"])
    assert len(packed) == 12  # 91 cells, one bit each, padded to whole bytes
    bits = np.unpackbits(np.frombuffer(packed, dtype=np.uint8))
    assert bits[0] == 1 and bits[3 * 13 + 2] == 1 and bits[13 * 7 - 1] == 1 and int(bits.sum()) == 11


def test_a_grid_decodes_to_the_same_cells_once_the_encoded_one_is_gone() -> None:
    data = json.loads(json.dumps(to_json(small_grid())))  # the encoded grid is garbage at once
    gc.collect()
    decoded = decode(data, OccupancyGrid)
    assert same(decoded, small_grid())
    made = {"@type": OCCUPANCY_GRID_MAP, "resolution": 0.1, "origin": [0, 0], "width": 3, "height": 2, "cells": "sA=="}
    grid = decode(made, OccupancyGrid)  # bits 101 100, padded: 0xB0
    assert grid.occupied.tolist() == [[True, False, True], [True, False, False]]
    assert grid.inflation_radius == DEFAULT_INFLATION_RADIUS and grid.inflated.all()  # 0.30 m covers the 3 x 2 cells


def test_values_from_elsewhere_may_leave_out_what_only_the_simulation_knows() -> None:
    robot = decode({"@type": ROBOT_LOCATION, "x": 1, "y": 2.5, "theta": 0}, RobotPoseEstimate)
    assert (robot.x, robot.y, robot.theta, robot.camera) == (1.0, 2.5, 0.0, "")
    path = decode({"@type": PATH, "waypoints": [[0, 0], [3, 4]]}, PlannedPath)
    assert (path.start, path.goal, path.length) == ((0.0, 0.0), (3.0, 4.0), 5.0)
    grasp = decode(
        {"@type": GRASP_POSE, "object": WORLD + "Pen", "height": 0.016, "width": 0.016, "approach": "top",
         "graspHeight": 0.008},
        GraspPlan,
    )  # fmt: skip
    assert grasp.model.name == "Pen" and grasp.model.grasp is GraspKind.TOP
    assert from_json({"@type": HOME + "Position", "x": 1.0, "y": 2.0, "theta": 0.5}) == Pose2D(1.0, 2.0, 0.5)
    assert decode({"@type": ROBOT_LOCATION, "x": 0, "y": 0, "theta": 0, "extra": [1]}, RobotPoseEstimate).x == 0.0


def good(concept: str) -> dict[str, Any]:
    value = next(v for v, c in SAMPLES if c == concept)
    return to_json(value, concept)


def broken(concept: str, key: str, bad: Any) -> dict[str, Any]:
    data = good(concept)
    if bad is DELETE:
        del data[key]
    else:
        data[key] = bad
    return data


DELETE = object()

MALFORMED: list[tuple[str, str, Any]] = [
    (ROBOT_LOCATION, "x", DELETE),
    (ROBOT_LOCATION, "x", "1.0"),
    (ROBOT_LOCATION, "theta", True),
    (ROBOT_LOCATION, "y", float("nan")),
    (ROBOT_LOCATION, "pixels", 2.5),
    (PERSON_POSITION, "y", None),
    (APPROACH_POSITION, "theta", DELETE),
    (OBJECT_POSITION_3D, "z", [0.7]),
    (OBJECT_POSITION_3D, "theta", "north"),
    (OBJECT_POSITION_3D, "size", [0.1, 0.1]),
    (OCCUPANCY_GRID_MAP, "cells", "not base64!"),
    (OCCUPANCY_GRID_MAP, "cells", "AAAA"),
    (OCCUPANCY_GRID_MAP, "width", 0),
    (OCCUPANCY_GRID_MAP, "height", 7.0),
    (OCCUPANCY_GRID_MAP, "resolution", -0.05),
    (OCCUPANCY_GRID_MAP, "origin", [0.0]),
    (OCCUPANCY_GRID_MAP, "inflationRadius", -1),
    (OCCUPANCY_GRID_MAP, "inflationRadius", 1e9),
    (PATH, "waypoints", []),
    (PATH, "waypoints", [[0.0, 1.0, 2.0]]),
    (PATH, "waypoints", DELETE),
    (MANIPULATION_PROPERTY, "approach", "sideways"),
    (MANIPULATION_PROPERTY, "object", ""),
    (GRASP_POSE, "graspHeight", DELETE),
    (GRASP_POSE, "width", "narrow"),
    (COLOUR_FEATURE, "colour", 3),
    (COLOUR_FEATURE, "colour", ""),
    (OBJECT_FEATURE, "colourFeature", DELETE),
]


@pytest.mark.parametrize(
    ("concept", "key", "bad"), MALFORMED, ids=lambda v: v.rsplit("#")[-1] if isinstance(v, str) else ""
)
def test_a_malformed_value_is_refused_naming_the_key(concept: str, key: str, bad: Any) -> None:
    with pytest.raises(MalformedValueError) as raised:
        from_json(broken(concept, key, bad))
    error = raised.value
    assert isinstance(error, SimulationError) and isinstance(error, ValueError)
    assert error.key == key and error.concept == concept
    assert repr(key) in str(error) and "expected" in str(error) and concept.rsplit("#")[-1] in str(error)


@pytest.mark.parametrize(
    ("data", "key"),
    [
        (None, "(value)"),
        ([1.0, 2.0], "(value)"),
        ({"x": 1.0, "y": 2.0}, "@type"),
        ({"@type": 7}, "@type"),
        ({"@type": HOME + "Spaceship", "x": 1.0}, "@type"),
        ({"@id": 3, "@type": HOME + "Pen"}, "@id"),
        ({"@type": OBJECT_FEATURE, "colourFeature": {"@type": ROBOT_LOCATION, "x": 0, "y": 0, "theta": 0}}, "@type"),
    ],
)
def test_what_is_not_a_typed_value_at_all_is_refused(data: Any, key: str) -> None:
    with pytest.raises(MalformedValueError) as raised:
        from_json(data)
    assert raised.value.key == key


def test_a_value_of_another_type_than_the_component_takes_is_refused_with_the_types_it_takes() -> None:
    with pytest.raises(MalformedValueError, match="PersonPosition, PersonLocation") as raised:
        decode(good(ROBOT_LOCATION), PersonEstimate)
    assert raised.value.key == "@type" and raised.value.value == ROBOT_LOCATION


def test_encoding_refuses_what_json_cannot_carry() -> None:
    with pytest.raises(MalformedValueError, match="'theta'"):
        to_json(RobotPoseEstimate(1.0, 2.0, math.inf, "CeilingCamera01", 0.0, 1))
    with pytest.raises(ValueError, match="not of Path"):
        to_json(Pose2D(1.0, 2.0), PATH)
    with pytest.raises(TypeError):
        to_json((1.0, 2.0))  # type: ignore[arg-type]


def test_a_component_decodes_at_its_boundary_and_fails_its_step_on_a_malformed_input() -> None:
    context = SimContext(None, None)  # type: ignore[arg-type]  (the planner reads neither world nor store)
    planner = SimComponent("planner", SKILLS["PlanPathAStar"], "HomeServer01")
    planner.initialise(context)
    start = {"@type": ROBOT_LOCATION, "x": 0.3, "y": 2.3, "theta": 0.0}  # as a remote localiser might say it
    goal = to_json(Pose2D(0.3, 4.7, 0.0), APPROACH_POSITION)
    planner.begin({"map": to_json(small_grid()), "start": start, "goal": goal})
    assert planner.update() is Status.SUCCEEDED, planner.reason
    path = planner.outputs["path"]
    assert path["@type"] == PATH and json.loads(json.dumps(path)) == path
    assert path["waypoints"][0] == [0.25, 2.25] and path["waypoints"][-1] == [0.25, 4.75]  # around the wall
    planner.begin({"map": broken(OCCUPANCY_GRID_MAP, "cells", "AAAA"), "start": start, "goal": goal})
    assert planner.update() is Status.FAILED
    assert "'cells'" in planner.reason and "OccupancyGridMap" in planner.reason


def test_every_type_with_a_shape_is_documented() -> None:
    text = DOC.read_text(encoding="utf-8")
    kinds = {type(v) for v, _ in SAMPLES} - {Designator}
    for kind in kinds:
        for concept in concepts_of(kind):
            assert f"`home:{concept.rsplit('#')[-1]}`" in text, concept


def test_a_type_of_a_misspelt_prefix_is_refused_with_the_name_meant() -> None:
    """A component's ``"@type": "hom:Opened"`` was refused as "expected an IRI or a prefixed name", leaving
    its author to find the slip; the refusal now says which prefix is unknown and the name it may mean."""
    with pytest.raises(MalformedValueError, match=r"hom: is declared nowhere .*did you mean home:Opened\?"):
        check(HOME + "DoorStatus", {"@type": "hom:Opened"})
