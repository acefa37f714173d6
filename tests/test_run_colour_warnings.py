"""A run's colour warnings are of what it perceived (actions/colour_warnings.py): the things its plans'
perceiving and grasping steps are given, and those a camera looked for, not the names its report mentions.
The task asks for a home:WritingInstrument (the report never names the pen or its class) and has a cup
among its inputs that no step takes (the report names home:Cup); both are painted at an edge. No task is
run here: tests/test_turtle_tasks_colours.py checks what two runs perceived."""

from __future__ import annotations

import json
from collections.abc import Iterator
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from cbrs.actions.colour_warnings import looking_devices, perceived_things, run_colour_risks
from cbrs.actions.composer import Composer
from cbrs.actions.runner import RunResult
from cbrs.kb import KnowledgeBase, Statement
from cbrs.kb.colour_risk import colour_risks
from cbrs.kb.colour_windows import SIMULATED_LIGHTING, ColourWindow, hsv
from cbrs.kb.namespaces import PREFIXES

HOME, SVC, WORLD = PREFIXES["home"], PREFIXES["svc"], PREFIXES["world"]
TASK = """@prefix cbrs: <https://w3id.org/cbrs/core#> .
@prefix home: <https://w3id.org/cbrs/home#> .
@prefix req:  <https://w3id.org/cbrs/requirement#> .
@prefix svc:  <https://w3id.org/cbrs/service#> .

req:FetchAWritingInstrument a cbrs:Requirement ;
    cbrs:requestedBy svc:P3DX01 ; cbrs:deviceName "P3DX01" ;
    cbrs:serviceName "FetchAWritingInstrument" ; cbrs:serviceCategory "Delivery" ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "thing" ; cbrs:parameterType home:WritingInstrument ] ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "person" ; cbrs:parameterType home:Person ] ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "colourOfMarker" ;
            cbrs:parameterType home:ColourOfMarker ] ;
        cbrs:hasInput [ a cbrs:Parameter ; cbrs:parameterName "cup" ; cbrs:parameterType home:Cup ] ;
        cbrs:hasPrecondition [ a cbrs:Precondition ; cbrs:conditionSubject home:MobileRobot ;
            cbrs:conditionPredicate home:hasMarker ; cbrs:conditionObject home:ColourMarker ] ;
        cbrs:hasEffect [ a cbrs:Effect ; cbrs:conditionSubject home:WritingInstrument ;
            cbrs:conditionPredicate home:isWith ; cbrs:conditionObject home:Person ] ] .
"""
EDGES = {"Pen": "0.10 0.45 0.85 1", "Cup": "0.85 0.25 0.08 1"}  # hue 212 (blue 210-250), 13 (red 345-15)


def _repaint(thing: str, rgba: str) -> str:
    return (
        f"DELETE {{ GRAPH graph:map {{ world:{thing} home:rgba ?old }} }} INSERT {{ GRAPH graph:map {{ world:{thing} "
        f'home:rgba "{rgba}" }} }} WHERE {{ GRAPH graph:map {{ world:{thing} home:rgba ?old }} }}'
    )


@pytest.fixture(scope="module")
def task_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("task") / "fetch_a_writing_instrument.ttl"
    path.write_text(TASK, encoding="utf-8")
    return path


@pytest.fixture(scope="module")
def kb(task_file: Path) -> Iterator[KnowledgeBase]:
    """The bundled home with the task, and the pen and the cup painted at the edges of their windows."""
    kb = KnowledgeBase.open(":memory:")
    kb.load([task_file], "requirements")
    for thing, rgba in EDGES.items():
        kb.update(_repaint(thing, rgba))
    yield kb
    kb.close()


def test_the_warnings_are_of_what_the_plan_perceives_not_what_its_report_names(kb: KnowledgeBase) -> None:
    assert [risk.thing for risk in colour_risks(kb)] == [WORLD + "Cup", WORLD + "Pen"]  # both at an edge
    composition = Composer(kb).compose("FetchAWritingInstrument")
    assert composition.plan is not None
    result = RunResult(composition, None)  # the plan alone: what it perceives is known before it runs
    report = json.dumps(result.to_dict())
    # why a search of the report went wrong: it names the cup's class (an input no step takes), never the pen's
    assert HOME + "Cup" in report and HOME + "Pen" not in report and WORLD + "Pen" not in report
    assert perceived_things(kb, result) == {WORLD + "Pen", WORLD + "Person", WORLD + "P3DX01MarkerColours"}
    assert [risk.thing for risk in run_colour_risks(kb, result)] == [WORLD + "Pen"]
    # what the run looked for counts too, whatever the plan; with no plan and nothing looked for, nothing
    assert [risk.thing for risk in run_colour_risks(kb, result, [WORLD + "Cup"])] == [WORLD + "Cup", WORLD + "Pen"]
    assert run_colour_risks(kb, RunResult(replace(composition, plan=None), None)) == []


def test_the_looking_devices_are_the_cameras_and_the_robot_a_camera_is_on(kb: KnowledgeBase) -> None:
    cameras = {SVC + name for name in ("CeilingCamera01", "CeilingCamera02", "Kinect01")}
    assert looking_devices(kb) == frozenset(cameras | {SVC + "CytonDualArm01"})  # the Kinect is mounted on it


@pytest.fixture(scope="module")
def world(kb: KnowledgeBase) -> Iterator[Any]:
    from cbrs.kb.semantic_map import SemanticMap
    from cbrs.sim.world import open_world

    with open_world(seed=0, semantic_map=SemanticMap.read(kb)) as built:
        yield built


def test_the_simulation_says_what_a_camera_looked_for(kb: KnowledgeBase, world: Any) -> None:
    """A check of a cup's water looks for the cup and the water; tracking the person, for the person."""
    from cbrs.sim import services
    from cbrs.sim.components import SimEnvironment
    from cbrs.sim.values import designator

    environment = SimEnvironment(world, kb)
    assert environment.looked_for() == frozenset()  # the look at everything before a plan is not counted
    environment.context.given = {"cup": designator(WORLD + "Cup", HOME + "Cup")}
    environment.verify(None, Statement(HOME + "Cup", HOME + "contains", HOME + "Water"), {})
    assert environment.looked_for() == {WORLD + "Cup", WORLD + "Water"}
    services.track(environment.context, {}, "CeilingCamera01")
    assert environment.looked_for() == {WORLD + "Cup", WORLD + "Water", WORLD + "Person"}


def test_the_renderer_shades_a_paint_as_the_warnings_do(world: Any) -> None:
    """The Kinect sees the pen's top and a side turned from the light: its pixels are as bright as
    SIMULATED_LIGHTING says, the paint's byte times the face's factor, cut down to a byte."""
    from cbrs.sim.perception import segment

    frame = world.camera("Kinect01").capture()
    u, v = frame.project(np.array([world.pose("Pen").position]))[0]
    mask = segment(frame.rgb, ColourWindow("probe", 212.0, 5.0, 0.55, 0.0))  # the pen's hue, no floor of brightness
    rows, cols = np.nonzero(mask)
    near = (np.abs(rows - v) < 20) & (np.abs(cols - u) < 20)
    brightness = set(frame.rgb[rows[near], cols[near]].max(axis=1).tolist())
    _, _, value = hsv(tuple(float(part) for part in EDGES["Pen"].split()))
    light = SIMULATED_LIGHTING
    assert brightness == {round(light.seen(value, light.lit) * 255), round(light.seen(value, light.shaded) * 255)}
