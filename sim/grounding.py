"""What a value a step is given means in the home.

A value between steps is plain JSON (:mod:`sim.values`); a designator (``{"@id": ...}``) names a thing
of the semantic map. These read what a component needs of it (the object's size, colour and grasps,
a place's extent and docking pose) and say which of the task's inputs, and which person, a step works
on: the person is the one given to it, else the one the task designates, else the home's only one.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import replace
from typing import Any

from cbrs.actions.plan import Plan, PlanStep
from cbrs.kb.person_choice import PersonError, person_for
from cbrs.kb.semantic_map import Person, SemanticMap, Thing, local_name
from cbrs.sim.context import SimContext, SkillFailed
from cbrs.sim.geometry import Pose2D, Region
from cbrs.sim.grasping import ObjectModel
from cbrs.sim.values import GraspPlan, Manipulation, from_json


def thing_iri(value: Any, what: str) -> str:
    if isinstance(value, dict) and isinstance(value.get("@id"), str):
        return str(value["@id"])
    raise SkillFailed(f"expected a thing of the world for {what}, got {value!r}")


def manipulation_of(ctx: SimContext, value: Any) -> Manipulation:
    """How to handle an object: from the semantic map for a designator, else as a ManipulationProperty
    or GraspPose value carries it (an earlier step, maybe a remote one, looked it up)."""
    if isinstance(value, dict) and "@id" in value:
        iri = thing_iri(value, "an object")
        obj = ctx.map.objects.get(iri)
        if obj is None:
            raise SkillFailed(f"the semantic map has no shape, size or grasp for {local_name(iri)}")
        return Manipulation.of(obj)
    found = from_json(value)
    if isinstance(found, (GraspPlan, Manipulation)):
        # The value names one approach; the map has the class's others to fall back on, after it, and a
        # box's footprint (a value carries one width, which depends on how the hand turns to a box).
        obj = ctx.map.objects.get(found.object)
        if obj is None:
            return Manipulation(found.object, found.model)
        known = ObjectModel.of(obj)
        model = found.model if found.model.approaches else found.model.preferring(known.preference)
        return Manipulation(found.object, replace(model, footprint=known.footprint))
    raise SkillFailed(f"expected an object, its manipulation property or its grasp, got {value!r}")


def model_of(ctx: SimContext, value: Any) -> ObjectModel:
    return manipulation_of(ctx, value).model


def place_of(ctx: SimContext, value: Any, what: str) -> Thing:
    iri = thing_iri(value, what)
    thing = ctx.map.things.get(iri)
    if thing is None:
        raise SkillFailed(f"the semantic map gives no extent for {local_name(iri)} ({what})")
    return thing


def thing_region(thing: Thing) -> Region:
    box = thing.box
    return Region(thing.name, box.min_x, box.max_x, box.min_y, box.max_y, box.min_z, box.max_z)


def docking_pose(thing: Thing) -> Pose2D:
    if thing.dock is None:
        raise SkillFailed(f"the semantic map gives no docking pose at {thing.name}")
    return Pose2D(thing.dock.x, thing.dock.y, thing.dock.yaw)


def task_inputs_of(step: PlanStep, steps: Mapping[int, PlanStep]) -> set[str]:
    """The task's inputs a step works on: those bound to its inputs, directly or through the steps
    that compute them (an arm's grasp pose comes from the object the task names)."""
    found: set[str] = set()
    todo, seen = [step], {step.index}
    while todo:
        current = todo.pop()
        for binding in current.inputs:
            source = binding.source
            if source.step is None:
                found.add(source.name)
            elif source.step not in seen and source.step in steps:
                seen.add(source.step)
                todo.append(steps[source.step])
    return found


def people_given(smap: SemanticMap, plan: Plan, step: PlanStep, values: Mapping[str, Any]) -> list[str]:
    """The map's people among the task's inputs a step works on (directly or through earlier steps)."""
    steps = {each.index: each for each in plan.steps}
    found = [values.get(name) for name in sorted(task_inputs_of(step, steps))]
    return [str(v["@id"]) for v in found if isinstance(v, dict) and str(v.get("@id")) in smap.people]


def meant_person(ctx: SimContext) -> Person:
    """The person the running step means (``kb.person_choice.person_for``): the one given to it or to a step
    it takes a value from, else the one the task designates, else the home's only person."""
    plan, step = ctx.plan, ctx.step
    given = people_given(ctx.map, plan, step, ctx.given) if plan is not None and step is not None else []
    try:
        return person_for(ctx.map, ctx.component or "the running step", given or ctx.designated)
    except PersonError as error:  # refused before the run (``SimEnvironment.given``); a re-plan fails the step
        raise SkillFailed(str(error)) from None
