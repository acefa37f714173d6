"""``cbrs plan`` and ``cbrs run``: thin commands over the composer and the runner."""

from __future__ import annotations

import contextlib
import difflib
import json
import os
import socket
import sys
import time
from collections import Counter
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, NoReturn

import click

from cbrs.actions.base_choice import BaseChoice, BaseTies, choose_in_map
from cbrs.actions.breaker import late_answers_awaited, settle_late_answers
from cbrs.actions.colour_warnings import run_colour_risks
from cbrs.actions.components import Registry
from cbrs.actions.composer import ComposeConfig, Composer, CompositionResult, Objective, PlanStatus, store_plan
from cbrs.actions.decomposition_notes import UnfollowedOrdering
from cbrs.actions.errors import UngroundedGoalError
from cbrs.actions.events import Event
from cbrs.actions.faults import RandomFaults, planned_faults
from cbrs.actions.graph import parameter_names, statement_text
from cbrs.actions.model import ActionLibrary
from cbrs.actions.plan import Binding, Plan, PlanStep
from cbrs.actions.replanning import ReplanPolicy
from cbrs.actions.runner import (
    GoalCheck,
    Replan,
    RunResult,
    run_task,
    ungrounded,
    unrunnable_steps,
)
from cbrs.actions.task_preconditions import PreconditionCheck
from cbrs.app import App, parse_iri, pass_app
from cbrs.extras import installed, require
from cbrs.kb import Advertisement, KnowledgeBase, RemoteStoreError
from cbrs.kb.errors import KnowledgeBaseError
from cbrs.kb.namespaces import shorten
from cbrs.kb.semantic_map import SemanticMap, UnresolvedDesignatorError
from cbrs.kb.store import Term
from cbrs.output import table
from cbrs.settings import setting
from cbrs.task_names import task_iri

if TYPE_CHECKING:
    from cbrs.bridge_client import BridgeClient

_IGNORE_AREAS = click.option(  # cbrs plan and cbrs run alike
    "--ignore-areas",
    is_flag=True,
    help=(
        "Compose without the service effective area rule: any component may serve a step, wherever the"
        " task's things are (ComposeConfig.respect_area off)."
    ),
)
_PROTECT = click.option(  # cbrs plan and cbrs run alike
    "--protect/--no-protect",
    default=ComposeConfig().protect,
    show_default=True,
    help=(
        "Check the plan by progression over its steps' add and delete effects, its parts as they will run one"
        " after the other, and achieve again a statement a step needs that an earlier step deleted, or refuse"
        " the plan naming it; --no-protect: the plan as extracted, left to the run's checks and re-plan"
        " (ComposeConfig.protect)."
    ),
)
_MAX_REACHIEVED = click.option(
    "--max-reachieved",
    type=click.IntRange(min=0),
    default=ComposeConfig().max_reachieved,
    show_default=True,
    metavar="N",
    help=(
        "With --protect, how many statements may be achieved again, per extraction and per plan joined from"
        " parts, before the plan is refused (ComposeConfig.max_reachieved)."
    ),
)
_NEAR_MISSES = click.option(
    "--near-misses",
    type=click.IntRange(min=0),
    default=ComposeConfig().near_misses,
    show_default=True,
    metavar="N",
    help=(
        "With no plan, name for each unmet need at most N components that come close: their output or effect"
        " is a near class of the need's (the same parts, or a sibling; docs/composition.md, Near misses);"
        " 0: none (ComposeConfig.near_misses)."
    ),
)
_BASE_TIES = click.option(
    "--base-ties",
    type=click.Choice([t.value for t in BaseTies]),
    default=BaseTies.NEAREST.value,
    show_default=True,
    help=(
        "In a home of several mobile bases, how plans of one cost and similarity for different bases are told"
        " apart: nearest, the base with the shortest route (round walls and furniture in the map) to where its"
        " plan first drives it, then the first by IRI;"
        " iri, the first by IRI (docs/simulation.md, A home with no mobile base)."
    ),
)

_OBJECTIVE = click.option(
    "--objective",
    type=click.Choice([o.value for o in Objective]),
    default=Objective.SIMILARITY.value,
    show_default=True,
    help=(
        "Choose the component for each step by highest similarity (estimated response time breaks ties), or by"
        " lowest cost: the stated cbrs:cost where every candidate states one, else the estimated response time"
        " (similarity breaks ties); the plan says what decided each step (docs/composition.md, Which cost)."
    ),
)


def _compose_config(
    ignore_areas: bool, protect: bool, max_reachieved: int, near_misses: int, **more: Any
) -> ComposeConfig:
    """What the composition options of ``cbrs plan`` and ``cbrs run`` ask for."""
    return ComposeConfig(
        respect_area=not ignore_areas,
        protect=protect,
        max_reachieved=max_reachieved,
        near_misses=near_misses,
        **more,
    )


@click.command()
@click.argument("task")
@click.option(
    "--json",
    "as_json",
    is_flag=True,
    help=(
        "Print the plan (or what is unsatisfied) as JSON; with a plan, its steps cbrs run cannot run in the"
        " simulated home now (unrunnable), those it reaches only with --bridge (over_bridge), and what it"
        " would refuse or plan without for what the map lacks (unmapped: a camera it does not place, a thing"
        " the task names that it does not hold)."
    ),
)
@click.option(
    "--draw",
    "drawing",
    type=click.Path(dir_okay=False, path_type=Path),
    help="Draw the service resource graph and the plan to FILE.svg or FILE.png.",
)
@_OBJECTIVE
@click.option("--no-store", is_flag=True, help="Do not record the plan in the plans graph.")
@_IGNORE_AREAS
@_PROTECT
@_MAX_REACHIEVED
@_NEAR_MISSES
@_BASE_TIES
@pass_app
def plan(
    app: App,
    task: str,
    as_json: bool,
    drawing: Path | None,
    objective: str,
    no_store: bool,
    ignore_areas: bool,
    protect: bool,
    max_reachieved: int,
    near_misses: int,
    base_ties: str,
) -> None:
    """Compose a plan for TASK: a requirement or action (req:FetchMyPen, act:RobotArmServeACup, or a bare name).

    Exits with status 1 when no plan exists, after saying which need no component meets and which
    components come close to it (--near-misses). The plan is
    composed over every advertisement; a note follows it for each step cbrs run cannot run in the
    simulated home now (no skill for its service, no live component to call, a camera the map does not
    place), which the run plans without, and for each thing the task names that the map does not hold,
    for which the run refuses the task. In a home of several mobile bases the plan works one, chosen as
    cbrs run chooses it, and says which and why. These are read from the store: no world is built.
    """
    if drawing is not None and drawing.suffix.lower() not in (".svg", ".png"):
        raise click.BadParameter(f"{drawing.name!r} must end in .svg or .png", param_hint="--draw")
    actions = ActionLibrary.from_kb(app.kb)  # read once: the task's name and the composer take it
    requested = task_iri(app.kb, task, actions)  # an unknown name is refused before the composer reads the store
    config = _compose_config(ignore_areas, protect, max_reachieved, near_misses, objective=Objective(objective))
    composer = Composer(app.kb, config, actions=actions)
    facts = app.kb.select("map_facts")  # read once: the bases, and what the map lacks
    result, chosen = choose_in_map(composer, requested, composer.compose(requested), BaseTies(base_ties), facts)
    if result.plan is not None and not no_store:
        try:
            store_plan(app.kb, result.plan)
        except RemoteStoreError as error:
            if error.status not in (401, 403):
                raise
            raise click.ClickException(
                f"{error}\nthe plan was composed but the server refused to record it: send its update token"
                " (CBRS_UPDATE_TOKEN), or add --no-store to only see the plan"
            ) from None
    if drawing is not None:
        require("eval", "cbrs plan --draw")
        from cbrs.actions.draw import draw  # matplotlib is slow to import; only when asked

        draw(result, drawing)
    here = _not_here(app.kb, result.plan, composer.advertisements, composer.config) if result.plan is not None else None
    unmapped = _unmapped(app.kb, composer, result.plan, facts) if result.plan is not None else None
    if as_json:
        found = result.to_dict()
        if chosen is not None:
            found["base"] = chosen.to_dict()
        if here is not None:
            found.update(here.to_dict())
        if unmapped is not None:
            found.update(unmapped.to_dict())
        click.echo(json.dumps(found, indent=2))
    else:
        notes = (here.text() if here is not None else "") + (unmapped.text() if unmapped is not None else "")
        click.echo(plan_text(result) + _base_note(chosen) + notes)
    if drawing is not None and not as_json:
        click.echo(f"drawing written to {drawing}")
    if result.status is not PlanStatus.PLANNED:
        raise SystemExit(1)


@dataclass(frozen=True)
class _NotHere:
    """The plan's steps ``cbrs run`` cannot run in the simulated home now, with why, and those it reaches
    only over a bridge (live components in other processes): ``cbrs plan`` composes over every
    advertisement, the run over those it can run, so a plan alone would promise too much."""

    unrunnable: tuple[tuple[PlanStep, str], ...]
    bridged: tuple[PlanStep, ...]

    def to_dict(self) -> dict[str, Any]:
        return {
            "unrunnable": [{"step": s.index, "component": s.component, "why": why} for s, why in self.unrunnable],
            "over_bridge": [{"step": s.index, "component": s.component} for s in self.bridged],
        }

    def text(self) -> str:
        lines = [
            f"\nnote: step {s.index} {shorten(s.component)} cannot run in the simulated home now: {why}; cbrs run"
            " plans without it"
            for s, why in self.unrunnable
        ]
        lines += [
            f"\nnote: step {s.index} {shorten(s.component)} is a live component in another process: cbrs run"
            " reaches it with --bridge ws://HOST:PORT of the server it registered with"
            for s in self.bridged
        ]
        return "".join(lines)


def _not_here(
    kb: KnowledgeBase, plan: Plan, advertisements: Sequence[Advertisement], config: ComposeConfig
) -> _NotHere | None:
    """What of ``plan`` the simulated home cannot run now (None without the [sim] part, which runs
    nothing): the runner's own check, over the simulation's skills (no world is built) and the
    components registered live; ``advertisements``, those the plan was composed over, read once, and
    ``config`` how (the unavailable live components a plan without the steps would use are found so)."""
    if not installed("sim"):
        return None
    from cbrs.sim.components import implementations

    live = {iri for iri, state in kb.liveness.states().items() if state.live}
    runnable = set(implementations(kb, advertisements=advertisements).names()) | live
    bridged = tuple(step for step in plan.steps if step.component in live)
    return _NotHere(unrunnable_steps(kb, plan, runnable, advertisements=advertisements, config=config), bridged)


@dataclass(frozen=True)
class _Unmapped:
    """What ``cbrs run`` would plan without or refuse for what the semantic map lacks, read from the store
    alone (the run's own checks, no world built): the plan's steps whose component looks with a camera
    the map does not place (``sim.run_checks.unplaced_cameras``: the run plans without it, or a table-top
    finder's step fails when it looks), and each class of thing the task names, in a goal or an input,
    of which the map holds nothing (``actions.runner.ungrounded``: the run refuses the task). Before,
    only the run found them, after building the world."""

    cameras: tuple[tuple[PlanStep, str, str, bool], ...]  # step, camera, why, whether the run plans without it
    things: tuple[UnresolvedDesignatorError | UngroundedGoalError, ...]

    def to_dict(self) -> dict[str, Any]:
        found: list[dict[str, Any]] = [
            {
                "kind": "camera",
                "step": step.index,
                "component": step.component,
                "camera": camera,
                "why": why,
                "planned_without": without,
            }
            for step, camera, why, without in self.cameras
        ]
        for error in self.things:
            if isinstance(error, UngroundedGoalError):
                found.append({"kind": "goal", "goal": error.goal, "concept": error.concept, "why": str(error)})
            else:
                found.append({"kind": "input", "concept": error.concept, "why": str(error)})
        return {"unmapped": found}

    def text(self) -> str:
        lines = [
            f"\nnote: step {step.index} {shorten(step.component)} cannot run in the simulated home now: {why};"
            + (" cbrs run plans without it" if without else " cbrs run plans it, and the step fails when it looks")
            for step, _, why, without in self.cameras
        ]
        lines += [f"\nnote: cbrs run refuses the task: {error}" for error in self.things]
        return "".join(lines)


def _base_note(chosen: BaseChoice | None) -> str:
    """In a home of several mobile bases, the one the plan works and why (``actions.base_choice``)."""
    if chosen is None:
        return ""
    return f"\nnote: the plan works {shorten(chosen.base)}, as cbrs run would choose it: {chosen.why}"


def _unmapped(kb: KnowledgeBase, composer: Composer, plan: Plan, facts: Sequence[Mapping[str, Term]]) -> _Unmapped:
    """What of ``plan`` ``cbrs run`` would plan without or refuse for what the map lacks: the things from
    the store alone; the cameras with the [sim] part only (its skills say which components look with a
    camera). ``facts``: the rows of ``map_facts``."""
    things = ungrounded(kb, composer.index, plan, facts)
    cameras: list[tuple[PlanStep, str, str, bool]] = []
    if installed("sim"):
        from cbrs.sim.run_checks import map_cameras, unplaced_cameras

        placed = map_cameras(kb, facts)
        used = {step.component for step in plan.steps}
        unplaced = unplaced_cameras(kb, [ad for ad in composer.advertisements if ad.iri in used], placed)
        cameras = [(step, *unplaced[step.component]) for step in plan.steps if step.component in unplaced]
    return _Unmapped(tuple(cameras), things)


def plan_text(result: CompositionResult) -> str:
    """The plan as a table of steps with their sources, or the unsatisfied needs."""
    name = shorten(result.task)
    if result.plan is None:
        orders = all(isinstance(u, UnfollowedOrdering) for u in result.unsatisfied)  # a need is met, not the order
        lines = [f"{name}: no plan. {'Why' if orders and result.unsatisfied else 'What no component provides'}:"]
        lines += [f"  - {u.text()}" for u in result.unsatisfied]
        lines += [f"note: {n}" for n in result.notes]  # the task's decomposition not followed
        return "\n".join(lines)
    plan: Plan = result.plan
    how = {
        "direct": "composed directly",
        "matched": "matched to one component by the matchmaker",
        "achieved": "nothing to do: every effect holds already",
    }.get(plan.method, "decomposed into " + ", ".join(map(_part_name, plan.sub_actions)))
    steps = f"{len(plan.steps)} step{'' if len(plan.steps) == 1 else 's'}"
    head = f"{name}: planned ({how}), {steps}, mean similarity {plan.similarity:.3f}, cost {plan.cost:g} s"
    rows = []
    for step in plan.steps:
        sources = "; ".join(_source(b) for b in step.bindings) or "-"
        alternatives = ", ".join(shorten(a) for a in step.alternatives) or "-"
        rows.append(
            [
                str(step.index),
                shorten(step.component),
                shorten(step.action) if step.action else "-",
                sources,
                alternatives,
            ]
        )
    goals = "\n".join(f"  {_source(g)}" for g in plan.goals)
    columns = ["#", "component", "action", "inputs and preconditions from", "alternatives"]
    notes = _unused_note(result.unused_inputs, result) + _ranking_note(result)
    notes += "".join(f"\nnote: {n}" for n in result.notes)  # the task's decomposition not followed
    return f"{head}\n{table(columns, rows)}\nGoals:\n{goals}{notes}"


def _part_name(part: str) -> str:
    """A part of a decomposed plan as the output names things: a sub-action shortened, and a goal's part (the
    task's IRI and ``/goal1``, as the composer names it) by the task's shortened name and its goal, which
    :func:`shorten` left whole (``https://example.org/lab15#SetTheTableForOne/goal1``: no prefixed name has
    a slash)."""
    task, slash, goal = part.rpartition("/")
    if slash and goal.startswith("goal") and goal.removeprefix("goal").isdigit():
        return f"{shorten(task)}/{goal}"
    return shorten(part)


_RANKED_BY = {
    "cbrs:cost": "the stated cbrs:cost",
    "responseTime": "the estimated response time",
    "similarity": "similarity",
    "level": "the forward level",
    "iri": "IRI",
}


def _ranking_note(result: CompositionResult) -> str:
    """With ``--objective cost``, what chose each step's component (``PlanStep.ranked_by``): a lab that
    states a ``cbrs:cost`` sees whether it was compared. The default objective adds nothing, so its
    output stays as it was; the JSON says it for both."""
    if result.objective is Objective.SIMILARITY or result.plan is None:
        return ""
    by: dict[str, list[str]] = {}
    for step in result.plan.steps:
        if step.ranked_by is not None:
            by.setdefault(step.ranked_by, []).append(str(step.index))
    if not by:
        return f"\nnote: --objective {result.objective.value}: no step had more than one component to choose from"
    said = "; ".join(f"{_RANKED_BY.get(metric, metric)} at step {', '.join(steps)}" for metric, steps in by.items())
    return f"\nnote: --objective {result.objective.value}: the component was chosen by {said} (others: no choice)"


def _unused_note(unused: Sequence[tuple[str, str]], composition: CompositionResult | None = None) -> str:
    """A note naming the task's inputs no plan took (``CompositionResult.unused_inputs`` for a plan,
    ``RunResult.unused_inputs`` for a run; docs/composition.md); none: no note. An input whose class
    another input of the task has, which the plan did take, is said to be passed over for that one: the
    note said "no component takes a thing of that class" of a researcher's second station, where the
    fare lookup took the first station for both of its own."""
    if not unused:
        return ""
    twins = _taken_twins(composition)
    alike = [(name, type_) for name, type_ in unused if twins.get(type_)]
    other = [(name, type_) for name, type_ in unused if not twins.get(type_)]
    notes = ""
    if other:
        named = ", ".join(f"{name} ({shorten(type_)})" for name, type_ in other)
        notes += (
            f"\nnote: no step takes the task's input {named}: no component takes a thing of that class (a"
            " destination must be a home:Place, say), so the plan does without it"
        )
    for name, type_ in alike:
        taken = ", ".join(twins[type_])
        others = "the task's other input" if len(twins[type_]) == 1 else "the task's other inputs"
        notes += (
            f"\nnote: no step takes the task's input {name} ({shorten(type_)}): each step's need of that class"
            f" was given {taken}, {others} of the class (docs/composition.md, 'Extracting the plan'), so the"
            " plan does without it"
        )
    return notes


def _taken_twins(composition: CompositionResult | None) -> dict[str, list[str]]:
    """The names of the task's inputs that a step of the plan takes, by their class."""
    if composition is None or composition.plan is None or not composition.attempts:
        return {}
    plan = composition.plan
    inputs = composition.attempts[0].requirement.inputs
    classes = dict(zip(parameter_names(inputs), (parameter.type for parameter in inputs), strict=True))
    taken = {b.source.name for step in plan.steps for b in step.bindings if b.source.step is None}
    found: dict[str, list[str]] = {}
    for name in sorted(taken & classes.keys()):
        found.setdefault(classes[name], []).append(name)
    return found


def _source(binding: Binding) -> str:
    if binding.source.step is None:  # a goal the world meets at the start (actions.composer) says so
        origin = "world" if binding.source.name == "world" else "requirement"
    else:
        origin = f"#{binding.source.step}"
    if binding.role == "input":
        return f"{binding.name} <- {origin}.{binding.source.name}"
    return f"{binding.name} <- {origin}"


@click.command()
@click.argument("task")
@click.option("--gui", is_flag=True, help="Show the pybullet window (default: headless).")
@click.option("--seed", default=0, show_default=True, type=int, help="Seed of the world's small perturbations.")
@click.option(
    "--fail",
    "faults",
    multiple=True,
    metavar="COMPONENT_IRI",
    help="Make this component fail whenever it is invoked (repeatable); prefixed names work.",
)
@click.option(
    "--fault-rate",
    type=click.FloatRange(0.0, 1.0),
    default=0.0,
    show_default=True,
    help="Break each component the plan may use with this probability, after a random amount of work.",
)
@click.option(
    "--fault-seed",
    type=int,
    help="Seed of the random faults (default: --seed); the same seed breaks the same components.",
)
@click.option(
    "--repeat-failures",
    type=click.IntRange(min=0),
    default=1,
    show_default=True,
    help=(
        "How many times a re-plan may run into the same failure (same component, inputs and kind) when nothing"
        " it depends on has moved; a plan around the failed component is tried first."
    ),
)
@click.option(
    "--bridge",
    metavar="URL",
    help=(
        "The rosbridge websocket of the cbrs server live components are connected to (ws://127.0.0.1:9090):"
        " the run calls them through it. Without it only the simulated components run; sends"
        " CBRS_UPDATE_TOKEN, when set, to be authorised."
    ),
)
@click.option(
    "--json",
    "as_json",
    is_flag=True,
    help="Print the plan, the execution report and the answers (the values of the task's outputs) as JSON.",
)
@click.option(
    "--record",
    type=click.Path(dir_okay=False, path_type=Path),
    help=(
        "Record the run to FILE (.gif; .mp4 or .webm need ffmpeg): 640x480, a frame every 0.5 simulated s,"
        " each captioned with the step; also draws the paths top-down to FILE-path.png."
    ),
)
@_IGNORE_AREAS
@_PROTECT
@_MAX_REACHIEVED
@_NEAR_MISSES
@_BASE_TIES
@_OBJECTIVE
@pass_app
def run(
    app: App,
    task: str,
    gui: bool,
    seed: int,
    faults: tuple[str, ...],
    fault_rate: float,
    fault_seed: int | None,
    repeat_failures: int,
    bridge: str | None,
    as_json: bool,
    record: Path | None,
    ignore_areas: bool,
    protect: bool,
    max_reachieved: int,
    near_misses: int,
    base_ties: str,
    objective: str,
) -> None:
    """Plan TASK, then execute it in the simulated home, step by step, failing over where needed.

    Exits with status 1 when there is no plan or the run fails; a failed run names the requirement
    it could not meet and every component tried for it. A task no plan can come of, whatever the robots
    perceive, is refused before the simulated home is built (docs/execution.md); cbrs plan TASK notes
    what the run will plan without or refuse.
    """
    require("sim", "cbrs run")
    from cbrs.sim.components import SimEnvironment, implementations  # pybullet loads only for this command
    from cbrs.sim.recording import Recorder, RecordingError, check_target
    from cbrs.sim.world import open_world
    from cbrs.sim_sensors import SensorsTakenError, provide_sensors
    from cbrs.tasks import refusal_in_home

    if gui:
        missing = display_problem(os.environ)
        if missing:  # pybullet would exit the process with status 1, saying nothing useful
            raise click.UsageError(
                f"--gui needs a display, but {missing}; run without --gui (headless), or under xvfb-run"
            )
    if record is not None:
        try:  # an unknown format, or a video with no ffmpeg, fails before anything runs
            check_target(record)
        except RecordingError as error:
            raise click.BadParameter(str(error), param_hint="--record") from None
    failing = [parse_iri(f, "--fail") for f in faults]
    actions = ActionLibrary.from_kb(app.kb)  # read once: the task's name and the composer take it
    iri = task_iri(app.kb, task, actions)  # an unknown task fails before the world is built
    if failing:
        _check_failing(app.kb, failing, bridged=bridge is not None)  # so does a mistyped --fail

    transport = _bridge(bridge) if bridge else None
    start = time.perf_counter()
    recorder: Recorder | None = None
    config = _compose_config(ignore_areas, protect, max_reachieved, near_misses, objective=Objective(objective))
    composer = Composer(app.kb, config, actions=actions)
    with contextlib.ExitStack() as held:
        if transport is not None:
            held.callback(transport.close)
            held.callback(_settle_late_answers, transport)  # before the close (a stack unwinds last first)
        # A task no plan could come of is refused before the world is built (a second or more of pybullet),
        # as a server's run refuses it
        no_plan = refusal_in_home(app.kb, iri, composer, transport)
        if no_plan is not None:
            wall = time.perf_counter() - start
            bridged = transport is not None
            before = implementations(app.kb, transport=transport, advertisements=composer.advertisements)
            _say_refused(app.kb, no_plan, before, seed, as_json, wall, bridged, composer.advertisements)
        world = held.enter_context(open_world(seed=seed, gui=gui, semantic_map=SemanticMap.read(app.kb)))
        if transport is not None:  # devices' programs read this world's sensors on the bridge until it ends
            try:
                held.enter_context(provide_sensors(transport, world))
            except SensorsTakenError as error:  # another home answers them: a run needing none goes on
                click.echo(f"note: {error}", err=True)
        environment = SimEnvironment(world, app.kb, transport)
        unknown = [f for f in failing if f not in environment.registry]
        if unknown:
            kind = "component" if transport is not None else "simulated component"  # what this run can invoke
            raise click.BadParameter(f"no {kind} {', '.join(map(shorten, unknown))}", param_hint="--fail")
        if record is not None:
            recorder = Recorder(world, title=task)

        def follow(event: Event) -> None:
            if recorder is not None:
                recorder.on_event(event)
            if not as_json and event.topic == "/cbrs/task_progress":
                click.echo(_progress(event.message), err=False)

        policy = RandomFaults(seed if fault_seed is None else fault_seed, fault_rate) if fault_rate > 0 else None
        if recorder is not None:
            recorder.start()
        try:
            result = run_task(
                app.kb,
                iri,
                environment,
                failing,
                composer=composer,
                on_event=follow,
                fault_policy=policy,
                replan_policy=ReplanPolicy(max_repeats=repeat_failures),
                base_ties=BaseTies(base_ties),
            )
        except KnowledgeBaseError as error:  # refused before anything moved (out of reach, ambiguous...)
            if not as_json:
                raise
            # a script asked for JSON: it gets JSON for a refusal too, as /cbrs/run_task words it
            refused = {"task": iri, "status": "error", "error": f"{type(error).__name__}: {error}", "seed": seed}
            click.echo(json.dumps(refused, indent=2))
            click.echo(f"Error: {error}", err=True)
            raise SystemExit(1) from None
        finally:
            if recorder is not None:
                recorder.stop()
        sim_seconds = world.time
    wall = time.perf_counter() - start
    recorded = None
    if recorder is not None and record is not None:
        try:
            recorded = recorder.save(record)
        except RecordingError as error:
            raise click.ClickException(str(error)) from None
    warnings = run_colour_risks(app.kb, result, environment.looked_for())  # what it looked for, at risk by colour
    if as_json:
        found = result.to_dict()
        found["seed"] = seed
        found["sim_seconds"] = round(sim_seconds, 3)
        found["warnings"] = [risk.to_dict() for risk in warnings]
        if policy is not None:
            found["random_faults"] = {"seed": policy.seed, "rate": policy.rate, "planned": _planned(policy, result)}
        click.echo(json.dumps(found, indent=2))
    else:
        if policy is not None:
            planned = ", ".join(
                f"{shorten(f['component'])} after {f['after_ticks']} ticks" for f in _planned(policy, result)
            )
            click.echo(f"random faults (seed {policy.seed}, rate {policy.rate}): {planned or 'none'}")
        click.echo(run_text(result, sim_seconds, wall))
        for risk in warnings:
            click.echo(f"warning: {risk.text()}")
        if recorded is not None:
            click.echo(
                f"recording written to {recorded.video} ({recorded.frames} frames over {recorded.seconds:.1f} s"
                f" simulated); paths drawn to {recorded.path_map}"
            )
    if not result.succeeded:
        _note_unreached(app.kb, environment.registry, bridged=transport is not None)
        raise SystemExit(1)


def _say_refused(
    kb: KnowledgeBase,
    result: RunResult,
    registry: Registry,
    seed: int,
    as_json: bool,
    wall: float,
    bridged: bool,
    advertisements: Sequence[Advertisement],
) -> NoReturn:
    """Say a run has no plan, as a run that built the world says it (nothing simulated), and exit 1."""
    if as_json:
        found = result.to_dict()
        found["seed"] = seed
        found["sim_seconds"] = 0.0
        click.echo(json.dumps(found, indent=2))
    else:
        click.echo(run_text(result, 0.0, wall))
    _note_unreached(kb, registry, bridged, advertisements)
    raise SystemExit(1)


def _note_unreached(
    kb: KnowledgeBase, registry: Registry, bridged: bool, advertisements: Sequence[Advertisement] | None = None
) -> None:
    """After a run that did not succeed: name the components in other processes it could not call."""
    unreached = [] if bridged else _live_unreached(kb, registry, advertisements)
    if unreached:
        kind = "is a component" if len(unreached) == 1 else "are components"
        click.echo(
            f"note: {', '.join(map(shorten, unreached))} {kind} in another process, which this run could not"
            " call: pass --bridge ws://HOST:PORT of the cbrs server it is connected to",
            err=True,
        )


def _check_failing(kb: KnowledgeBase, failing: list[str], bridged: bool) -> None:
    """Refuse a --fail that names no component the run could invoke, with the nearest names, before the
    world is built (seconds): the simulation's components (cameras aside: the world's check after it is
    built still applies), and with --bridge those in other processes."""
    from cbrs.sim.components import implementations

    known = set(implementations(kb).names())
    if bridged:
        known |= {ad.iri for ad in kb.advertisements() if ad.bridge_port is not None}
    unknown = [f for f in failing if f not in known]
    if not unknown:
        return
    names = sorted(shorten(k) for k in known)
    said = []
    for component in unknown:
        near = difflib.get_close_matches(shorten(component), names, n=2)
        said.append(shorten(component) + (f" (did you mean {' or '.join(near)}?)" if near else ""))
    kind = "component" if bridged else "simulated component"  # without --bridge it can invoke no other
    raise click.BadParameter(f"no {kind} {', '.join(said)}", param_hint="--fail")


def _bridge(url: str) -> BridgeClient:
    """A connection to the bridge live components answer on; a clear error when there is none."""
    from cbrs.bridge_client import BridgeClient, BridgeClosedError

    if not url.startswith(("ws://", "wss://")):
        raise click.BadParameter(f"{url!r} is not a websocket URL (ws://HOST:PORT)", param_hint="--bridge")
    try:
        return BridgeClient(url, setting("update_token").resolve())
    except BridgeClosedError as error:
        raise click.BadParameter(str(error), param_hint="--bridge") from None


def _settle_late_answers(transport: BridgeClient) -> None:
    """Wait (``late_answer_wait``) for the actuators whose calls the run gave up to answer, so that what
    they did is believed, before the connection closes and ends their calls unanswered; said on stderr."""
    awaited = late_answers_awaited(transport)
    wait = float(setting("late_answer_wait").resolve())
    if not awaited or wait <= 0:
        return
    names = ", ".join(shorten(service) for service in awaited)
    click.echo(f"waiting up to {wait:g} s for the answer of {names}, whose call was given up", err=True)
    left = settle_late_answers(transport, wait)
    if left:
        click.echo(f"no answer from {', '.join(map(shorten, left))}: what it did is not believed", err=True)


def _live_unreached(
    kb: KnowledgeBase, registry: Registry, advertisements: Sequence[Advertisement] | None = None
) -> list[str]:
    """The advertisements invoked through a bridge service (components in other processes) that the run
    had no implementation of: what ``--bridge`` would have let it call (``advertisements``: the store's,
    if just read)."""
    found = kb.advertisements() if advertisements is None else advertisements
    return sorted(ad.iri for ad in found if ad.iri not in registry and ad.bridge_port is not None)


def display_problem(environ: dict[str, str] | os._Environ[str]) -> str | None:
    """Why pybullet's window could not open here (None when an X display looks reachable).

    Only X11 needs checking: on macOS and Windows pybullet opens its own window.
    """
    if not sys.platform.startswith("linux"):
        return None
    display = environ.get("DISPLAY", "")
    if not display:
        return "DISPLAY is not set (no X server to show the window on)"
    host, _, rest = display.rpartition(":")
    number = rest.split(".", 1)[0]
    if not number.isdigit():
        return f"DISPLAY={display!r} is not an X display name such as :0"
    if host in ("", "unix"):
        path = f"/tmp/.X11-unix/X{number}"
        if os.path.exists(path) or _abstract_socket_answers(path):
            return None
        return f"no X server listens on DISPLAY={display} (no {path})"
    try:
        socket.create_connection((host, 6000 + int(number)), timeout=2).close()
    except OSError as error:
        return f"the X server of DISPLAY={display} cannot be reached ({error.strerror or error})"
    return None


def _abstract_socket_answers(path: str) -> bool:
    """Whether an X server listens on Linux's abstract socket of that name (as Xorg also does)."""
    with socket.socket(socket.AF_UNIX, socket.SOCK_STREAM) as probe:
        probe.settimeout(2)
        try:
            probe.connect("\0" + path)
        except OSError:
            return False
    return True


def _planned(policy: RandomFaults, result: RunResult) -> list[dict[str, Any]]:
    plan = result.composition.plan
    faults = planned_faults(policy, plan) if plan is not None else []
    return [{"component": f.component, "after_ticks": f.after_ticks} for f in faults]


def _progress(message: dict[str, Any]) -> str:
    if message["event"] == "replanning":
        return f"  re-planning (plan {message['plan']}) from what holds now: {message.get('reason', '')}"
    if message["event"] == "base_chosen":  # a home of several mobile bases (actions.base_choice)
        return f"  the plans work {shorten(message['base'])}: {message['why']}"
    if message["event"] == "awaiting":
        gone = ", ".join(map(shorten, message["components"]))
        return f"  waiting up to {message['seconds']:g} s for {gone} to register again before re-planning"
    if message["event"] == "passed_over":  # remote components whose calls timed out (actions.breaker)
        return "\n".join(f"  passing over {shorten(c)}: {why}" for c, why in sorted(message["components"].items()))
    if "step" not in message or "component" not in message:  # an event of a newer runner: said as it is
        return f"  {message['event']}: " + ", ".join(f"{k} {v}" for k, v in message.items() if k != "event")
    kind, step, component = message["event"], message["step"], shorten(message["component"])
    if kind == "step_started":
        return f"  step {step:>2}  {component} ..."
    if kind == "step_succeeded":
        return f"  step {step:>2}  {component} succeeded"
    nxt = f"; failing over to {shorten(message['failover'])}" if message.get("failover") else ""
    return f"  step {step:>2}  {component} FAILED: {message.get('reason', '')}{nxt}"


def run_text(result: RunResult, sim_seconds: float, wall_seconds: float) -> str:
    """The execution summary: one row per step, then the verdict."""
    if result.report is None:
        return plan_text(result.composition)
    report = result.report
    replaced = [
        f"plan {n} replaced after {sum(1 for s in r.report.steps if s.outcome == 'succeeded')} step(s): {r.reason}"
        + _avoided_text(r)
        for n, r in enumerate(result.replans, start=1)
    ]
    header = "\n".join(replaced + _passed_over_lines(result.passed_over))
    header += "\n" if header else ""
    rows = []
    for step in report.steps:
        tried = " -> ".join(shorten(a.component) for a in step.attempts) or shorten(step.planned)
        seconds = sum(a.seconds for a in step.attempts)
        checks = ", ".join("ok" if ok else ("FAILED" if ok is False else "-") for _, ok in step.effects) or "-"
        rows.append([str(step.index), tried, f"{seconds:.1f}", step.outcome, checks])
    verdict = f"{shorten(report.task)}: {report.status.value}"
    if report.reason:
        verdict += f" ({report.reason})"
    if result.stopped:
        verdict += f"; {result.stopped}"
    if result.executed and result.refuted:  # the robots believed it done; the world says otherwise
        verdict = f"{shorten(report.task)}: failed (the robots believed it done, but in the world "
        verdict += "; ".join(_refuted_text(goal) for goal in result.refuted) + ")"
    elif result.goals and all(goal.holds for goal in result.goals if goal.holds is not None):
        checked = sum(1 for goal in result.goals if goal.holds is not None)
        verdict += f"; {checked} goal(s) confirmed in the world" if checked else ""
        verdict += _unchecked_text(result) if result.executed else ""
    failovers = sum(1 for s in report.steps if s.failed_over)
    timing = f"{sim_seconds:.1f} s simulated, {wall_seconds:.1f} s wall, {failovers} failover(s)"
    timing += f", {len(result.replans)} re-plan(s)" if result.replans else ""
    steps = table(["#", "component", "sim s", "outcome", "effects checked"], rows)
    if not report.steps:  # every effect held already: no table of no steps
        steps = "nothing to do: every effect of the task holds already"
    note = _unused_note(result.unused_inputs, result.composition) + _ranking_note(result.composition)
    note += "".join(f"\nnote: {n}" for n in result.composition.notes)  # the decomposition not followed
    given = _preconditions_text(result.preconditions)
    return f"{header}{steps}\n{verdict}; {timing}{given}{_answers_text(result)}{note}"


def _refuted_text(goal: GoalCheck) -> str:
    """A goal the world contradicts: an effect that does not hold, or a delete effect whose statement still does."""
    if goal.deleted:
        return f"{statement_text(goal.statement)} still holds"
    return f"{statement_text(goal.statement)} does not hold"


def _unchecked_text(result: RunResult) -> str:
    """The goals nothing could check, said as such: a goal about a relation the environment has no test
    for (a lab's ``isInformedOf``) read as plainly "succeeded" as one the world confirmed."""
    unchecked = [goal for goal in result.goals if goal.holds is None]
    if not unchecked:
        return ""
    said = "; ".join(
        goal.text()
        + (": the robots believe it" if goal.believed else ": nothing checked it, its step's effect says it")
        for goal in unchecked
    )
    return f"; {len(unchecked)} goal(s) the world cannot check ({said})"


def _preconditions_text(checks: Sequence[PreconditionCheck]) -> str:
    """The task's own preconditions as the run found them, a line under the verdict
    (:func:`cbrs.tasks.preconditions_line`, the run page's words); none: no line."""
    from cbrs.tasks import preconditions_line

    line = preconditions_line(check.to_dict() for check in checks)
    return "\n" + line if line else ""


def _answers_text(result: RunResult) -> str:
    """The values the task's requirement asked for (its outputs), a line each: the answer to a task that
    asks a question (``req:RoomTemperature``), which the steps table alone does not show."""
    answers = result.answers
    if not answers:
        return ""
    return "\n" + ("Answer:" if len(answers) == 1 else "Answers:") + "".join(f"\n  {a.text()}" for a in answers)


def _passed_over_lines(passed: tuple[tuple[str, str], ...]) -> list[str]:
    """The components the last plan was composed without (a circuit breaker's or an actuator's rule), a
    line each with why; the reason names the component itself when it starts with its name."""
    if not passed:
        return []
    lines = ["the plan was composed without:"]
    for component, why in passed:
        name = shorten(component)
        lines.append(f"  {why}" if why.startswith(name) else f"  {name}: {why}")
    return lines


def _avoided_text(replan: Replan) -> str:
    """Which components the next plan goes without, and why: a component that failed, or one that gave
    the failed step its inputs (it may have worked; what it gave may be what failed)."""
    if not replan.avoided:
        return ""
    failed = {failure.component for failure in replan.failures}
    own = [c for c in replan.avoided if c in failed]
    producers = [c for c in replan.avoided if c not in failed]
    parts = [f"{', '.join(map(shorten, own))} (failed, nothing changed)"] if own else []
    if producers:
        parts.append(f"{', '.join(map(shorten, producers))} (gave the failed step its inputs)")
    return f"; the next plan avoids {' and '.join(parts)}"


DEMO_RUNS = (
    ("RobotArmServeACup", ()),
    ("FetchMyPen", ()),
    ("FetchMyPen", ("svc:LocateMobileRobot_CeilingCamera01",)),
)


def scenario_runs(
    kb: KnowledgeBase, seed: int = 0, progress: Callable[[str, int, int], None] | None = None
) -> tuple[str, bool]:
    """Run the paper's two scenarios headless (FetchMyPen also with its localiser failed): one row
    each, then the world graph; and whether every run succeeded. ``progress(stage, done, total)`` hears
    of each run before it starts (the three take 10-15 s, which the demo spent saying nothing)."""
    require("sim", "the demo's runs in the simulated home")
    from cbrs.kb.semantic_map import SemanticMap
    from cbrs.sim.components import SimEnvironment
    from cbrs.sim.world import open_world

    rows = []
    failed = 0
    composer = Composer(kb)
    for done, (task, faults) in enumerate(DEMO_RUNS):
        injected = f" (fail {', '.join(faults)})" if faults else ""
        if progress is not None:
            progress(f"running {task}{injected}", done, len(DEMO_RUNS))
        start = time.perf_counter()
        with open_world(seed=seed, semantic_map=SemanticMap.read(kb)) as world:
            result = run_task(kb, task, SimEnvironment(world, kb), [parse_iri(f) for f in faults], composer=composer)
            simulated = world.time
        wall = time.perf_counter() - start
        report = result.report
        steps = len(report.steps) if report else 0
        switched = Counter(
            f"{shorten(s.planned)} -> {shorten(s.component)}" for s in (report.steps if report else []) if s.failed_over
        )
        failovers = ", ".join(f"{n} x {what}" if n > 1 else what for what, n in switched.items())
        verified = sum(1 for s in (report.steps if report else []) for _, ok in s.effects if ok)
        status = report.status.value if report else "no plan"
        failed += 0 if result.succeeded else 1
        rows.append(
            [task + injected, str(steps), status, str(verified), f"{simulated:.1f}", f"{wall:.1f}", failovers or "-"]
        )
    facts = "\n".join(
        f"  ({shorten(r['thing'].value)}, {shorten(r['relation'].value)}, {shorten(r['other'].value)})"
        for r in kb.select("world_facts")
    )
    columns = ["task", "steps", "status", "effects verified", "sim s", "wall s", "failover"]
    verdict = f"\n{failed} of {len(rows)} runs did not succeed." if failed else ""
    graph = f"The world graph after the last run (cbrs query --name world_facts):\n{facts}"
    return f"{table(columns, rows)}{verdict}\n{graph}", failed == 0
