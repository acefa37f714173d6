"""A plan drives one mobile base: in a home of several, which one.

The composer chooses each step's component by the matchmaker alone, so with two bases' components
advertised a plan could navigate with one and deliver with the other, which no run can do (a run drives
one base). The map says which components are whose base (:func:`base_groups`: the advertisements whose
device is the base); the task is then composed once per base, the other bases' components left out, and
the best plan is taken: the least cost, then the greatest similarity, then (``BaseTies.NEAREST``) the base
with the least to drive to where its plan first takes it, round the walls and the furniture
(:class:`MapDrives`, :mod:`kb.floor_routes`; a base that cannot get there is not taken), then the first
base by IRI.
The cost is the advertised response time; under ``--objective cost``, when every step of every plan names
a component that states a ``cbrs:cost``, the plans' summed stated cost comes first (:class:`StatedCosts`),
as the composition ranked each step's candidates.
A task whose requirement names one of the bases is composed for that base alone: requested by it
(``cbrs:requestedBy``), else an input of the task designating it (:func:`named_base`). A home of one base
or none composes as before. ``cbrs run`` chooses so (``actions.runner``), and ``cbrs plan`` and the plans
page by the store alone (:func:`choose_in_map`): docs/simulation.md, "A home with no mobile base".
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, replace
from enum import Enum
from typing import Any, Literal

from cbrs.actions.composer import ComposeConfig, Composer, CompositionResult, Objective
from cbrs.actions.graph import stated_cost  # one reading of cbrs:cost, the composer's
from cbrs.actions.plan import Plan, PlanStep
from cbrs.actions.unavailable import name_unavailable
from cbrs.kb import Advertisement, KnowledgeBase, NotFoundError, Requirement
from cbrs.kb.floor_routes import Routes, RouteSettings
from cbrs.kb.home_check import NoDockingPoseError, docked_place
from cbrs.kb.namespaces import HOME, PREFIXES
from cbrs.kb.semantic_map import (
    AmbiguousDesignatorError,
    SemanticMap,
    UnresolvedDesignatorError,
    designate,
)
from cbrs.kb.semantic_map import local_name as _local
from cbrs.kb.store import Term

__all__ = [
    "BaseChoice",
    "BaseTies",
    "FirstDrive",
    "MapDrives",
    "StatedCosts",
    "base_groups",
    "choose_base",
    "choose_in_map",
    "map_bases",
    "named_base",
    "on_behalf",
    "stated_costs",
]

_NEAR = HOME + "isNear"  # a drive's effect: the robot comes near a place, an object or a person
_BASE_MARKS = frozenset({HOME + "hasPlatform", HOME + "hasMarker"})  # what makes a thing of the map a mobile base
_SAME = 1e-3  # metres: distances closer than this are alike


class BaseTies(Enum):
    """How plans of one cost and one similarity, for different bases, are told apart (``cbrs run`` and
    ``cbrs plan --base-ties``)."""

    NEAREST = "nearest"  # the least to drive, round walls and furniture, to where its plan first goes; then by IRI
    IRI = "iri"  # the first base by IRI


@dataclass(frozen=True)
class FirstDrive:
    """Where a base's plan first drives it, and how far: ``metres`` along the way round what stands in the
    map (:mod:`kb.floor_routes`), from the base's pose in the map to where its first drive goes (the things
    it approaches, their mean); ``straight``, the straight line in the floor's plane. ``metres`` None: the
    base cannot get there (``why``). ``measure`` "line": the map gives nothing to route on (``why``), and
    ``metres`` is the straight line."""

    step: int
    component: str
    towards: tuple[str, ...]  # the things, by IRI
    metres: float | None
    straight: float
    measure: Literal["route", "line"] = "route"
    why: str = ""

    def to_dict(self) -> dict[str, Any]:
        found = {
            "step": self.step,
            "component": self.component,
            "towards": list(self.towards),
            "metres": None if self.metres is None else round(self.metres, 3),
            "straight": round(self.straight, 3),
            "measure": self.measure,
        }
        return {**found, "why": self.why} if self.why else found


@dataclass(frozen=True)
class BaseChoice:
    """The base a run's plans work, why, and the other bases' components its compositions leave out.
    ``rule`` names what decided: requested, designated, only, cost, similarity, nearest, iri or none;
    ``drives``, each tied base's first drive when the distances were compared."""

    base: str
    why: str
    left_out: frozenset[str] = frozenset()
    rule: str = ""
    drives: tuple[tuple[str, FirstDrive | None], ...] = ()

    def to_dict(self) -> dict[str, Any]:
        found: dict[str, Any] = {"base": self.base, "why": self.why, "rule": self.rule}
        found["left_out"] = sorted(self.left_out)
        if self.drives:  # None: the base's plan drives to nothing the map places
            found["drives"] = [{"base": base, "drive": None if d is None else d.to_dict()} for base, d in self.drives]
        return found


Drive = Callable[[str, CompositionResult], FirstDrive | None]
"""A base's first drive in its own plan (``MapDrives``), None when it drives to nothing the map places."""

StatedCosts = Mapping[str, float | None]
"""Each component's stated ``cbrs:cost`` (None: it states none), given to :func:`choose_base` under
``--objective cost`` (:func:`stated_costs`); no mapping: the objective is similarity."""


def stated_costs(config: ComposeConfig, advertisements: Iterable[Advertisement]) -> StatedCosts | None:
    """The stated ``cbrs:cost`` of each of ``advertisements`` as ``config`` reads it (its
    ``unstated_cost`` for one that states none), or None when ``config`` ranks by similarity."""
    if config.objective is not Objective.COST:
        return None
    return {ad.iri: stated_cost(ad, config.unstated_cost) for ad in advertisements}


def _summed(plan: Plan, stated: StatedCosts) -> float | None:
    """``plan``'s stated cost: the sum over its steps, None when a step's component states none."""
    costs = [stated.get(step.component) for step in plan.steps]
    return None if any(cost is None for cost in costs) else round(sum(c for c in costs if c is not None), 9)


def choose_base(
    compose: Callable[[frozenset[str]], CompositionResult],
    composition: CompositionResult,
    groups: Mapping[str, frozenset[str]],
    named: str | None = None,
    drive: Drive | None = None,
    ties: BaseTies = BaseTies.NEAREST,
    stated: StatedCosts | None = None,
) -> tuple[CompositionResult, BaseChoice | None]:
    """``composition`` (composed over every component) kept, or replaced by the best one-base composition.

    ``compose`` composes the task without the components it is given; ``groups`` maps each base's IRI to
    its own components; ``named``: the base an input of the task designates, if one does; ``drive``
    measures a base's first drive, asked only of plans that cost alike and match alike (with ``ties``
    NEAREST); ``stated``: the components' stated costs under ``--objective cost`` (:func:`stated_costs`),
    whose sum over a plan's steps ranks the plans first when every plan's every step states one. Nothing
    changes (None) with fewer than two bases, for no plan (none over a part of the components either), and
    for a plan that no base's component could run (the arms' alone)."""
    plan = composition.plan
    if len(groups) < 2 or plan is None:
        return composition, None
    every = frozenset().union(*groups.values())
    if not any(c in every for step in plan.steps for c in step.candidates):
        return composition, None
    requester = composition.attempts[0].requirement.requested_by if composition.attempts else None
    if requester is not None and requester in groups:
        bases, said = [requester], f"the task's requirement is requested by {_local(requester)} (cbrs:requestedBy)"
        rule = "requested"
    elif named is not None and named in groups:
        bases, said, rule = [named], f"an input of the task designates {_local(named)}", "designated"
    else:
        bases, said, rule = sorted(groups), "", ""
    tried = {base: compose(every - groups[base]) for base in bases}
    planned = {base: found.plan for base, found in tried.items() if found.plan is not None}
    if not planned:
        first = bases[0]
        why = (
            f"{said}, and its components make no plan"
            if said
            else "no one base's components make a plan (the plan over every component mixed them: a run drives one)"
        )
        return tried[first], BaseChoice(first, why, every - groups[first], "none")
    sums = {base: _summed(plan, stated) for base, plan in planned.items()} if stated is not None else {}
    summed = {base: s for base, s in sums.items() if s is not None} if len(sums) > 1 else {}
    rank = _Rank(summed if len(summed) == len(sums) else {}, stated is not None)
    ranked = sorted(planned, key=lambda base: rank(planned[base], base))
    if said:
        return tried[ranked[0]], BaseChoice(ranked[0], said, every - groups[ranked[0]], rule)
    near = drive if ties is BaseTies.NEAREST else None
    best, why, rule, drives = _decide(ranked, planned, tried, bases, near, rank)
    why += rank.unstated() if rule != "only" else ""
    return tried[best], BaseChoice(best, why, every - groups[best], rule, drives)


@dataclass(frozen=True)
class _Rank:
    """How the bases' plans are ranked, lowest first: by ``summed`` stated cost (each base's, when every
    plan's every step states one: a unitless figure is compared only with its like), then advertised
    response time, then similarity, then IRI. ``objective_cost``: ``--objective cost`` was asked for."""

    summed: Mapping[str, float]
    objective_cost: bool

    def __call__(self, plan: Plan, base: str) -> tuple[Any, ...]:
        head = (self.summed[base],) if self.summed else ()
        return (*head, plan.cost, -plan.similarity, base)

    def alike(self, plan: Plan, base: str, other: Plan, other_base: str) -> bool:
        return self(plan, base)[:-1] == self(other, other_base)[:-1]

    def unstated(self) -> str:
        """Why the stated cost did not rank, said under ``--objective cost``."""
        if not self.objective_cost or self.summed:
            return ""
        return " (objective cost: not every step of the plans states a cbrs:cost, so response time ranks)"


def _decide(
    ranked: list[str],
    planned: Mapping[str, Plan],
    tried: Mapping[str, CompositionResult],
    bases: list[str],
    drive: Drive | None,
    rank: _Rank,
) -> tuple[str, str, str, tuple[tuple[str, FirstDrive | None], ...]]:
    """The base, why, the rule that decided, and the first drives compared (if they were)."""
    best = ranked[0]
    if len(ranked) == 1:
        others = ", ".join(_local(base) for base in bases if base != best)
        return best, f"only {_local(best)}'s components make a plan ({others}: none)", "only", ()
    second = ranked[1]
    mine, theirs = planned[best], planned[second]
    if rank.summed and rank.summed[best] != rank.summed[second]:
        why = (
            f"objective cost: its plan's stated cbrs:cost is the least: {rank.summed[best]:.3g} summed over its "
            f"{len(mine.steps)} steps, {_local(second)}'s {rank.summed[second]:.3g}"
        )
        return best, why, "stated-cost", ()
    alike_stated = f"the plans' stated cbrs:cost is alike ({rank.summed[best]:.3g}); " if rank.summed else ""
    if mine.cost != theirs.cost:
        why = (
            f"{alike_stated}its plan costs the least: {mine.cost:.3g} s of advertised response time, "
            f"{_local(second)}'s {theirs.cost:.3g} s"
        )
        return best, why, "cost", ()
    if mine.similarity != theirs.similarity:
        why = (
            f"{alike_stated}the plans cost alike ({mine.cost:.3g} s); its similarity is the greater: "
            f"{mine.similarity:.3f}, {_local(second)}'s {theirs.similarity:.3f}"
        )
        return best, why, "similarity", ()

    def head(other: str) -> str:
        return (
            f"{alike_stated}its plan and {other}'s cost alike ({mine.cost:g} s) and match alike ({mine.similarity:.3f})"
        )

    alike = head(_local(second))
    if drive is None:
        return best, f"{alike}: the first base by IRI", "iri", ()
    tied = [base for base in ranked if rank.alike(planned[base], base, mine, best)]
    drives = tuple((base, drive(base, tried[base])) for base in tied)
    unknown = [base for base, found in drives if found is None]
    if unknown:
        named = ", ".join(_local(base) for base in unknown)
        why = f"{alike}, and {named}'s plan drives to nothing the map places: the first base by IRI"
        return best, why, "iri", drives
    measured = {base: found for base, found in drives if found is not None}
    nearest, why = _nearest(measured, head)
    if nearest is None:
        return best, f"{alike}, {why}: the first base by IRI", "iri", drives
    return nearest, why, "nearest", drives


def _nearest(drives: Mapping[str, FirstDrive], alike: Callable[[str], str]) -> tuple[str | None, str]:
    """The base with the least to drive and why (``alike``: the words before, given the runner-up), or None
    and why not: none gets there, or the two nearest are as far. By the routes, unless one could not be laid
    (no grid: then by every base's straight line, one measure for all)."""
    by_line = any(found.measure == "line" for found in drives.values())
    metres = {base: found.straight if by_line else found.metres for base, found in drives.items()}
    cannot = sorted(base for base, away in metres.items() if away is None)
    stuck = "; ".join(f"{_local(base)} cannot get there ({drives[base].why})" for base in cannot)
    ranked = sorted((away, base) for base, away in metres.items() if away is not None)
    if not ranked:
        return None, f"and no base can get to where its first drive goes: {stuck}"
    (near, nearest) = ranked[0]
    found = drives[nearest]
    towards = ", ".join(_local(thing) for thing in found.towards)
    if by_line:
        lacking = next(f.why for f in drives.values() if f.measure == "line")
        how = f"in a straight line (the map gives no way round what stands: {lacking})"
    else:
        how = f"round what stands in the way ({found.straight:.2f} m in a straight line)"
    if len(ranked) == 1:
        others = ", ".join(_local(base) for base in cannot)
        return nearest, (
            f"{alike(others)}; it alone can get to {towards}, where its first drive "
            f"({_local(found.component)}) goes: {near:.2f} m from where it stands in the map, {how}; {stuck}"
        )
    next_near, runner_up = ranked[1]
    if next_near - near < _SAME:
        return None, f"and they stand as far from where their first drives go ({near:.2f} m)"
    theirs = drives[runner_up]
    also = "" if by_line else f" ({theirs.straight:.2f} m)"
    why = (
        f"{alike(_local(runner_up))}; it has the least to drive: {near:.2f} m from where it stands"
        f" in the map to {towards}, {how}, where its first drive ({_local(found.component)}) goes,"
        f" {_local(runner_up)}'s {next_near:.2f} m{also}"
    )
    return nearest, why + (f"; {stuck}" if stuck else "")


class MapDrives:
    """A base's first drive in its plan, measured in the semantic map (read on first use unless given):
    the first step of one of the base's own components whose effect brings a robot near something
    (``home:isNear``: a navigation), the task's inputs that step works on (directly or through the steps
    that compute its inputs: the pen whose place a locator infers), designated as a run designates them
    (preferring the requester's, else this base's), and of those the things the map places: a person
    where they start, a place at its docking pose (else its extent's centre), an object at the docking
    pose of what it stands on (where a drive to fetch it parks; else where it starts). The way from the
    base's pose in the map to their mean, round the walls, the furniture and the other bases
    (:class:`kb.floor_routes.Routes`, from the map alone: ``cbrs plan`` and ``cbrs run`` choose alike, and
    the seed moves the bases a little), or, where the map gives nothing to route on, the straight line."""

    def __init__(
        self,
        kb: KnowledgeBase,
        groups: Mapping[str, frozenset[str]],
        smap: SemanticMap | None = None,
        settings: RouteSettings | None = None,
    ):
        self.kb, self.groups, self._map, self.settings = kb, groups, smap, settings
        self._routes: Routes | None = None

    @property
    def map(self) -> SemanticMap:
        if self._map is None:
            self._map = SemanticMap.read(self.kb)
        return self._map

    @property
    def routes(self) -> Routes:
        if self._routes is None:
            self._routes = Routes(self.map, self.settings)
        return self._routes

    def __call__(self, base: str, found: CompositionResult) -> FirstDrive | None:
        plan, robot = found.plan, self.map.robots.get(base)
        if plan is None or robot is None:
            return None
        step = next((s for s in plan.steps if s.component in self.groups.get(base, ()) and _drives(s)), None)
        if step is None:
            return None
        things = self._things(base, found, _task_inputs(step, plan))
        points = {thing: point for thing in things if (point := self._where(thing)) is not None}
        if not points:
            return None
        x = sum(p[0] for p in points.values()) / len(points)
        y = sum(p[1] for p in points.values()) / len(points)
        route = self.routes.route(base, (x, y))
        measure: Literal["route", "line"] = "route" if route.grid else "line"  # line: nothing to route on, said why
        metres = route.metres if route.grid else route.straight
        return FirstDrive(step.index, step.component, tuple(sorted(points)), metres, route.straight, measure, route.why)

    def _things(self, base: str, found: CompositionResult, inputs: Iterable[tuple[str, str]]) -> set[str]:
        """The things the task's ``inputs`` (requirement, name) designate, as a run of ``base`` would."""
        requirements = {attempt.requirement.iri: attempt.requirement for attempt in found.attempts}
        things = set()
        for iri, name in sorted(inputs):
            requirement = requirements.get(iri) or _requirement(self.kb, iri)
            parameter = next((p for p in requirement.inputs if p.name == name), None) if requirement else None
            if requirement is None or parameter is None:
                continue
            try:
                things.add(designate(self.kb, parameter.type, prefer=requirement.requested_by or base))
            except (UnresolvedDesignatorError, AmbiguousDesignatorError):
                continue  # a run refuses it, naming it; here it places nothing
        return things

    def _where(self, thing: str) -> tuple[float, float] | None:
        smap = self.map
        if thing in smap.objects:
            start = smap.objects[thing].start
            support = smap.objects[thing].support
            try:
                place = docked_place(smap, thing, [support] if support else [])
            except NoDockingPoseError:
                place = None  # on something with no docking pose: a run refuses it; here, where it lies
            return (place.dock.x, place.dock.y) if place is not None and place.dock else (start.x, start.y)
        if thing in smap.people:
            return (smap.people[thing].start.x, smap.people[thing].start.y)
        place = smap.things.get(thing)
        if place is None:
            return None
        if place.dock is not None:
            return (place.dock.x, place.dock.y)
        return place.box.centre[:2]


def _drives(step: PlanStep) -> bool:
    """Whether ``step`` brings a robot near something (a navigation's effect)."""
    return any(effect.predicate == _NEAR for effect in step.effects)


def _task_inputs(step: PlanStep, plan: Plan) -> set[tuple[str, str]]:
    """The task's inputs (requirement, name) ``step`` works on, directly or through earlier steps."""
    steps = {each.index: each for each in plan.steps}
    found: set[tuple[str, str]] = set()
    todo, seen = [step], {step.index}
    while todo:
        for binding in todo.pop().inputs:
            source = binding.source
            if source.step is None:
                found.add((source.requirement or plan.requirement, source.name))
            elif source.step not in seen and source.step in steps:
                seen.add(source.step)
                todo.append(steps[source.step])
    return found


def _requirement(kb: KnowledgeBase, iri: str) -> Requirement | None:
    try:
        found = kb.description(iri)
    except NotFoundError:
        return None
    return found if isinstance(found, Requirement) else None


def named_base(kb: KnowledgeBase, composition: CompositionResult, groups: Mapping[str, Any]) -> str | None:
    """The base (one of ``groups``) an input of the task designates itself, if one does (a lab's class of
    which P3DX02 is the one thing): the task names its base so."""
    if not composition.attempts:
        return None
    requirement = composition.attempts[0].requirement
    for parameter in requirement.inputs:
        try:
            thing = designate(kb, parameter.type, prefer=requirement.requested_by)
        except (UnresolvedDesignatorError, AmbiguousDesignatorError):
            continue
        if thing in groups:
            return thing
    return None


def on_behalf(requirements: Mapping[str, Requirement], chosen: BaseChoice | None) -> dict[str, Requirement]:
    """``requirements`` as their inputs are designated in a run that drives ``chosen``: one no robot
    requests as if the chosen base did, so that a thing of which each base has one (the marker's colours
    a locator is given) is the chosen base's, the one the plan drives (docs/simulation.md, "A home with no
    mobile base")."""
    if chosen is None:
        return dict(requirements)
    return {
        iri: found if found.requested_by is not None else replace(found, requested_by=chosen.base)
        for iri, found in requirements.items()
    }


def base_groups(
    kb: KnowledgeBase, bases: Iterable[str], advertisements: Sequence[Advertisement] | None = None
) -> dict[str, frozenset[str]]:
    """Each base's own components: base IRI -> the IRIs of the advertisements whose device
    (``cbrs:device``, else by its ``cbrs:deviceName``) is that base, simulated or remote; ``advertisements``
    if read already, else the store's."""
    found: dict[str, set[str]] = {base: set() for base in bases}
    for ad in kb.advertisements() if advertisements is None else advertisements:
        device = ad.device or PREFIXES["svc"] + (ad.device_name or "")
        if device in found:
            found[device].add(ad.iri)
    return {base: frozenset(components) for base, components in sorted(found.items())}


def map_bases(kb: KnowledgeBase, facts: Sequence[Mapping[str, Term]] | None = None) -> set[str]:
    """The IRIs of the mobile bases the world will build, from the store alone: each thing the map gives a
    platform or a marker is one (``SemanticMap.robots``). ``facts``: the rows of ``map_facts`` when the caller
    has read them already."""
    rows = kb.select("map_facts") if facts is None else facts
    return {row["thing"].value for row in rows if row["property"].value in _BASE_MARKS}


def choose_in_map(
    composer: Composer,
    task: str | Requirement,
    composition: CompositionResult,
    ties: BaseTies = BaseTies.NEAREST,
    facts: Sequence[Mapping[str, Term]] | None = None,
) -> tuple[CompositionResult, BaseChoice | None]:
    """:func:`choose_base` as a run chooses, by the store alone (no world): the bases from the semantic map
    (:func:`map_bases`; ``facts``, its rows if read already), their components among the advertisements
    ``composer`` composes over; each base's plan composed as ``composition`` was (from the map, not the
    belief). ``cbrs plan``, the plans page, the bridge's /cbrs/plan and the task editor (a draft's
    ``Requirement``). Without a plan, the live components a plan would use that are unavailable now are
    named with why, as a run names them (:func:`actions.unavailable.name_unavailable`)."""
    kb = composer.kb
    if composition.plan is None:
        return name_unavailable(kb, composer.config, task, composition), None
    bases = map_bases(kb, facts)
    if len(bases) < 2:
        return composition, None
    groups = base_groups(kb, bases, composer.advertisements)

    def compose(without: frozenset[str]) -> CompositionResult:
        kept = [ad for ad in composer.advertisements if ad.iri not in without]
        one = Composer(kb, composer.config, index=composer.index, actions=composer.actions, advertisements=kept)
        return one.compose(task)

    named = named_base(kb, composition, groups)
    stated = stated_costs(composer.config, composer.advertisements)
    return choose_base(compose, composition, groups, named, MapDrives(kb, groups), ties, stated)
