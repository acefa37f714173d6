"""Which things a run's colour warnings are of: those its plans perceive, and those it looked for.

A thing painted where the cameras may not tell its colour (:mod:`kb.colour_risk`) matters to a run when a
camera looks for it by that colour. The things were once found by searching the run's report for the
names it mentions, so a thing a plan took by a class the report named otherwise was missed (the pen a
task asks for as a ``home:WritingInstrument``), and a thing merely named was warned of (a cup among
the task's inputs that no plan took). Now they come from what the run did (docs/simulation.md, "Colour
windows"):

* the things the plans' perceiving and grasping steps are given: a step runs on a camera of the map, or
  on a robot a camera is mounted on (whose grasps go by that camera's view); each of its inputs is
  followed back through the plan's data flow to the task's inputs it comes from, and each of those is
  the thing the map designates for its class, as the run's environment designates it
  (:func:`kb.semantic_map.designate_each`), or every thing of the class where the map designates none;
* the things the run's environment says a camera looked for (an environment's optional
  ``looked_for()``, the simulation's :meth:`sim.components.SimEnvironment.looked_for`): what a component
  recognised or tracked, and what the verification of a step's effects looked at (a container's water).
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import TYPE_CHECKING

from pyoxigraph import NamedNode

from cbrs.kb import KnowledgeBase, KnowledgeBaseError, NotFoundError, Requirement
from cbrs.kb.colour_risk import ColourRisk, colour_risks
from cbrs.kb.colour_windows import read_colour_windows
from cbrs.kb.semantic_map import designate_each

if TYPE_CHECKING:
    from cbrs.actions.plan import Plan, PlanStep
    from cbrs.actions.runner import RunResult

__all__ = ["looking_devices", "perceived_things", "run_colour_risks"]


def run_colour_risks(kb: KnowledgeBase, result: RunResult, looked_for: Iterable[str] = ()) -> list[ColourRisk]:
    """The colour risks of the things ``result``'s plans perceive or grasp, and of ``looked_for`` (the
    things its environment says a camera looked for): what ``cbrs run`` and a server's run report."""
    things = perceived_things(kb, result) | set(looked_for)
    return colour_risks(kb, things) if things else []  # no plan, nothing looked at: nothing to read


def perceived_things(kb: KnowledgeBase, result: RunResult) -> set[str]:
    """The things (IRIs) the steps of ``result``'s plans (each replaced one and the last) that run on a
    camera, or on a robot with a camera mounted on it, are given: each of their inputs followed back
    through the plan to the task's inputs it comes from, designated as the run designates them."""
    plans = [replan.plan for replan in result.replans]
    if result.composition.plan is not None:
        plans.append(result.composition.plan)
    if not plans:
        return set()
    devices = looking_devices(kb)
    inputs: set[tuple[str, str]] = set()  # (requirement, input name) the looking steps' inputs come from
    for plan in plans:
        for step in plan.steps:
            if step.device in devices:
                inputs |= _task_inputs(plan, step)
    known = {attempt.requirement.iri: attempt.requirement for attempt in result.composition.attempts}
    base = result.base.base if result.base is not None else None
    wanted: dict[tuple[str, str | None], None] = {}  # (class, the requesting robot), in order, once each
    for requirement_iri, name in sorted(inputs):
        requirement = known.get(requirement_iri) or _requirement(kb, requirement_iri)
        if requirement is None:
            continue
        for parameter in requirement.inputs:
            if parameter.name == name:  # one no robot requests is the chosen base's (actions.base_choice)
                wanted[(parameter.type, requirement.requested_by or base)] = None
    return {thing for concept, prefer in wanted for thing in _designated(kb, concept, prefer)}


def looking_devices(kb: KnowledgeBase) -> frozenset[str]:
    """The devices (IRIs) whose steps look by colour: the map's cameras, and the robots one is mounted on."""
    cameras = set(read_colour_windows(kb))
    mounted = {row["robot"].value for row in kb.select("mounted_cameras") if row["device"].value in cameras}
    return frozenset(cameras | mounted)


def _task_inputs(plan: Plan, step: PlanStep, visited: set[int] | None = None) -> set[tuple[str, str]]:
    """The task's inputs (requirement, name) ``step``'s inputs come from, through the steps that gave them."""
    visited = set() if visited is None else visited
    found: set[tuple[str, str]] = set()
    for binding in step.inputs:
        source = binding.source
        if source.step is None:
            if source.requirement:
                found.add((source.requirement, source.name))
        elif source.step not in visited:
            visited.add(source.step)
            found |= _task_inputs(plan, plan.step(source.step), visited)
    return found


def _requirement(kb: KnowledgeBase, iri: str) -> Requirement | None:
    try:
        description = kb.description(iri)
    except NotFoundError:
        return None  # recorded by another store's plan, say: nothing here names its inputs
    return description if isinstance(description, Requirement) else None


def _designated(kb: KnowledgeBase, concept: str, prefer: str | None) -> list[str]:
    """The thing the map designates for ``concept`` (for ``prefer``'s task), else every thing of it."""
    try:
        return designate_each(kb, [(concept, prefer)])
    except KnowledgeBaseError:  # none, or several the map cannot tell apart: each is a candidate
        return sorted({row["thing"].value for row in kb.select("designate", {"class": NamedNode(concept)})})
