"""A plan drives one mobile base: in a home of several, which one.

The composer chooses each step's component by the matchmaker alone, so with two bases' components
advertised a plan could navigate with one and deliver with the other, which no run can do (a run drives
one base). The environment says which components are whose base (``Environment.base_components``); the
task is then composed once per base, the other bases' components left out, and the best plan is taken:
the least cost, then the greatest similarity, then the first base by IRI. A task whose requirement names
one of the bases is composed for that base alone: requested by it (``cbrs:requestedBy``), else an input
of the task designating it (the caller's ``named``). A home of one base
or none composes as before (docs/simulation.md, "A home with no mobile base").
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

from cbrs.actions.composer import CompositionResult
from cbrs.actions.plan import Plan
from cbrs.kb.semantic_map import local_name as _local

__all__ = ["BaseChoice", "choose_base"]


@dataclass(frozen=True)
class BaseChoice:
    """The base a run's plans work, why, and the other bases' components its compositions leave out."""

    base: str
    why: str
    left_out: frozenset[str] = frozenset()

    def to_dict(self) -> dict[str, Any]:
        return {"base": self.base, "why": self.why, "left_out": sorted(self.left_out)}


def choose_base(
    compose: Callable[[frozenset[str]], CompositionResult],
    composition: CompositionResult,
    groups: Mapping[str, frozenset[str]],
    named: str | None = None,
) -> tuple[CompositionResult, BaseChoice | None]:
    """``composition`` (composed over every component) kept, or replaced by the best one-base composition.

    ``compose`` composes the task without the components it is given; ``groups`` maps each base's IRI to
    its own components; ``named``: the base an input of the task designates, if one does. Nothing changes
    (None) with fewer than two bases, for no plan (none over a part of the components either), and for a
    plan that no base's component could run (the arms' alone)."""
    plan = composition.plan
    if len(groups) < 2 or plan is None:
        return composition, None
    every = frozenset().union(*groups.values())
    if not any(c in every for step in plan.steps for c in step.candidates):
        return composition, None
    requester = composition.attempts[0].requirement.requested_by if composition.attempts else None
    if requester is not None and requester in groups:
        bases, said = [requester], f"the task's requirement is requested by {_local(requester)} (cbrs:requestedBy)"
    elif named is not None and named in groups:
        bases, said = [named], f"an input of the task designates {_local(named)}"
    else:
        bases, said = sorted(groups), ""
    tried = {base: compose(every - groups[base]) for base in bases}
    planned = {base: found.plan for base, found in tried.items() if found.plan is not None}
    if not planned:
        first = bases[0]
        why = (
            f"{said}, and its components make no plan"
            if said
            else "no one base's components make a plan (the plan over every component mixed them: a run drives one)"
        )
        return tried[first], BaseChoice(first, why, every - groups[first])
    ranked = sorted(planned, key=lambda base: _rank(planned[base], base))
    best = ranked[0]
    why = said or _why(best, ranked, planned, bases)
    return tried[best], BaseChoice(best, why, every - groups[best])


def _rank(plan: Plan, base: str) -> tuple[float, float, str]:
    return (plan.cost, -plan.similarity, base)


def _why(best: str, ranked: list[str], planned: Mapping[str, Plan], bases: list[str]) -> str:
    if len(ranked) == 1:
        others = ", ".join(_local(base) for base in bases if base != best)
        return f"only {_local(best)}'s components make a plan ({others}: none)"
    second = ranked[1]
    mine, theirs = planned[best], planned[second]
    if mine.cost != theirs.cost:
        return (
            f"its plan costs the least: {mine.cost:.3g} s of advertised response time, "
            f"{_local(second)}'s {theirs.cost:.3g} s"
        )
    if mine.similarity != theirs.similarity:
        return (
            f"the plans cost alike ({mine.cost:.3g} s); its similarity is the greater: {mine.similarity:.3f}, "
            f"{_local(second)}'s {theirs.similarity:.3f}"
        )
    return f"its plan and {_local(second)}'s cost alike and match alike: the first base by IRI"
