"""What re-planning remembers of a run's failures, so that it does not buy the same failure twice.

A step that failed for a deterministic reason (the same component, with the same inputs, in the same
world) fails again: composing afresh from an unchanged belief gives the same plan, and re-running it
spends the retry budget on a known outcome. But a plan that failed may succeed once the world has
changed: the simulation's pencil, taken askew at the edge of the left arm's reach, is let go and found
elsewhere by the re-perception, and the same plan then fetches it. So the memory keys each failure by
(component, what its inputs are bound to, kind of failure), compares the belief of the things the
failed step depended on at the failure and after the re-perception, and for a failure nothing has
changed since asks the composer first for a plan without its component; only when there is none does
the same plan run again, at most ``ReplanPolicy.max_repeats`` times (docs/execution.md#re-planning).
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

from cbrs.actions.belief import Observation
from cbrs.actions.composer import CompositionResult
from cbrs.actions.errors import ActionsError
from cbrs.actions.executor import ExecutionReport, Executor
from cbrs.actions.plan import Plan, PlanStep
from cbrs.reasoner.names import local_name

_MEASURE = re.compile(r"[-+]?\d+(?:\.\d+)?(?:e[-+]?\d+)?")


class ReplanPolicyError(ActionsError, ValueError):
    """A re-planning policy was given an impossible parameter (a negative bound or tolerance)."""

    def __init__(self, name: str, value: object, why: str) -> None:
        super().__init__(f"{name} = {value!r}: {why}")
        self.name = name
        self.value = value


@dataclass(frozen=True)
class ReplanPolicy:
    """How a re-plan treats a failure met before in the run with nothing it depends on changed since.

    ``avoid``: first compose without the components of such failures (an alternative route).
    ``max_repeats``: how many times a plan may still run into the same failure (same component, same
    bound inputs, same kind) with an unchanged belief; past it the run stops and says why. One repeat
    by default: a failure can hinge on what the belief does not hold (a component's own state, a
    remote one's connection), and the bundled tests rely on a second try of a broken component.
    ``tolerance``: metres a thing must have moved in the belief to count as changed (the cameras place
    a centre within about 1 cm; a hand lets go up to 2 cm above a surface).
    ``reconnect_grace``: seconds (wall clock) a re-plan waits for a failed live component that went
    unavailable (its program exited or hung) to register again before planning without it: a
    supervisor restarts a program in about a second, and a plan around a device that is back a moment
    later is worse than the wait; the default lease (3 s) is the time cbrs already gives a component to
    answer its heartbeat.
    """

    avoid: bool = True
    max_repeats: int = 1
    tolerance: float = 0.03
    reconnect_grace: float = 3.0

    def __post_init__(self) -> None:
        if self.max_repeats < 0:
            raise ReplanPolicyError("max_repeats", self.max_repeats, "a number of repeats cannot be negative")
        if not self.tolerance >= 0.0:
            raise ReplanPolicyError("tolerance", self.tolerance, "a distance cannot be negative")
        if not 0.0 <= self.reconnect_grace <= 600.0:
            raise ReplanPolicyError("reconnect_grace", self.reconnect_grace, "a wait is 0 to 600 seconds")


@dataclass(frozen=True)
class Failure:
    """One failed attempt of a step: the component, what its inputs were bound to, and the kind of
    failure (its reason with the measurements masked: 'rad 0.42' and 'rad 0.40' are one kind)."""

    step: int
    component: str
    inputs: tuple[tuple[str, str], ...]  # (input name, the thing it named or the step output it came from)
    reason: str
    things: frozenset[str]  # the things of the world the inputs named: what the step depended on
    producers: tuple[str, ...] = ()  # the components whose outputs the step was given, in plan order

    @property
    def kind(self) -> str:
        return _MEASURE.sub("#", self.reason)

    @property
    def key(self) -> tuple[str, tuple[tuple[str, str], ...], str]:
        return (self.component, self.inputs, self.kind)

    def text(self) -> str:
        bound = ", ".join(f"{name} <- {local_name(value)}" for name, value in self.inputs) or "no inputs"
        return f"step {self.step} ({local_name(self.component)} with {bound}): {self.reason}"

    def to_dict(self) -> dict[str, Any]:
        return {
            "step": self.step,
            "component": self.component,
            "inputs": {name: value for name, value in self.inputs},
            "reason": self.reason,
            "things": sorted(self.things),
            "producers": list(self.producers),
        }


@dataclass
class Decision:
    """What the memory made of a failed plan: the next composition (None: stop, saying ``stopped``),
    the components it was composed without, and the failures it may meet again."""

    composition: CompositionResult | None
    avoided: tuple[str, ...] = ()
    repeated: tuple[Failure, ...] = ()
    stopped: str = ""


@dataclass
class FailureMemory:
    """The failures of one run, counted while nothing they depend on changes."""

    policy: ReplanPolicy = field(default_factory=ReplanPolicy)
    counts: dict[tuple[str, tuple[tuple[str, str], ...], str], int] = field(default_factory=dict)
    avoided: set[str] = field(default_factory=set)

    def failures(self, executor: Executor, report: ExecutionReport, seen: Observation) -> list[Failure]:
        """The failed step's attempts (and the components skipped as broken), with what they depended on."""
        unmet = report.unmet
        if unmet is None:
            return []  # stopped for another reason (ticks ran out): nothing to learn about a step
        step = executor.plan.step(unmet.step)
        inputs = executor.inputs_for(step)
        known = set(seen.types) | set(seen.positions)
        things = frozenset(name for value in inputs.values() for name in _names(value) if name in known)
        bound = _bound(step, inputs, executor.plan, known)
        done = {report.index: report.component for report in report.steps}
        sources = sorted({b.source.step for b in step.inputs if b.source.step is not None and b.source.step in done})
        producers = tuple(dict.fromkeys(done[index] for index in sources))  # in plan order
        return [
            Failure(step.index, attempt.component, bound, attempt.reason, things, producers) for attempt in unmet.tried
        ]

    def changed(self, failure: Failure, before: Observation, after: Observation) -> bool:
        """Whether the belief of what the failed step depended on differs after the re-perception (every
        thing, when its inputs named none): a thing moved, appeared or went, or what is believed of it
        changed (its relations as their subject: the table a carry failed to reach has not changed
        because the cup that was in the hand is back on it)."""
        things = failure.things or frozenset(before.positions) | frozenset(after.positions)
        for thing in things:
            was, now = before.positions.get(thing), after.positions.get(thing)
            if (was is None) != (now is None):
                return True
            if was is not None and now is not None and math.dist(was, now) > self.policy.tolerance:
                return True
        return _facts(before.facts, things) != _facts(after.facts, things)

    def decide(
        self,
        failures: Iterable[Failure],
        before: Observation,
        after: Observation,
        compose: Callable[[frozenset[str]], CompositionResult],
    ) -> Decision:
        """The next composition after a failed plan: the usual one when the belief of what failed has
        changed; otherwise first one without the failed components, then the usual one as long as its
        repeats stay within the policy's bound; or none, with the reason."""
        unchanged: list[Failure] = []
        for failure in failures:
            if self.changed(failure, before, after):
                self.counts.pop(failure.key, None)
                self.avoided.discard(failure.component)
                continue
            self.counts[failure.key] = self.counts.get(failure.key, 0) + 1
            self.avoided.add(failure.component)
            unchanged.append(failure)
        if not unchanged:
            return Decision(compose(frozenset()))
        if self.policy.avoid:
            around = compose(frozenset(self.avoided))
            if around.plan is not None:
                return Decision(around, tuple(sorted(self.avoided)))
            # No way round the step that failed: what it was given may be what was wrong (a camera that
            # placed the object half a metre off fails the arm, not itself). Try without one of its
            # producers at a time, the latest first (the grasp planner before it may have no stand-in).
            failed = {f.component for f in unchanged}
            producers = dict.fromkeys(p for f in unchanged for p in reversed(f.producers) if p not in failed)
            for producer in producers:
                around = compose(frozenset({producer}) | (self.avoided - failed))
                if around.plan is not None:
                    return Decision(around, (producer,))
        usual = compose(frozenset())
        if usual.plan is None:
            return Decision(usual)
        used = {component for step in usual.plan.steps for component in step.candidates}
        again = tuple(f for f in unchanged if f.component in used)
        over = [f for f in again if self.counts[f.key] > self.policy.max_repeats]
        if over:
            return Decision(None, repeated=again, stopped=self._stopped(over[0]))
        return Decision(usual, repeated=again)

    def _stopped(self, failure: Failure) -> str:
        times = self.counts[failure.key]
        around = "no plan avoids it" if self.policy.avoid else "avoiding it is switched off"
        return (
            f"re-planning stopped: {failure.text()}; met {times} time(s) with nothing it depends on changed"
            f" ({_listed(failure.things) or 'no thing of the world moved'}); {around}, and the next plan would run"
            f" {local_name(failure.component)} again (repeats allowed: {self.policy.max_repeats})"
        )


def _listed(things: Iterable[str]) -> str:
    return ", ".join(sorted(local_name(t) for t in things))


def _names(value: Any) -> Iterable[str]:
    """The strings inside an input value (a designator's @id, a grasp's object, ...)."""
    if isinstance(value, str):
        yield value
    elif isinstance(value, Mapping):
        for item in value.values():
            yield from _names(item)
    elif isinstance(value, (list, tuple)):
        for item in value:
            yield from _names(item)


def _bound(step: PlanStep, inputs: Mapping[str, Any], plan: Plan, known: set[str]) -> tuple[tuple[str, str], ...]:
    """Each input's binding: the thing of the world it names, else the output (or task input) it came
    from; never the measured numbers, which the belief comparison covers."""
    found = []
    for binding in step.inputs:
        named = sorted(n for n in _names(inputs.get(binding.name)) if n in known)
        if named:
            found.append((binding.name, named[0]))
        elif binding.source.step is not None:
            producer = plan.step(binding.source.step).component
            found.append((binding.name, f"{producer}.{binding.source.name}"))
        else:
            found.append((binding.name, f"{binding.source.requirement or 'task'}.{binding.source.name}"))
    return tuple(sorted(found))


def _facts(facts: Iterable[tuple[str, str, str]], things: frozenset[str]) -> set[tuple[str, str, str]]:
    return {fact for fact in facts if fact[0] in things}
