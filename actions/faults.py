"""Injected component failures: fixed ones (``--fail``) and seeded random ones (``--fault-rate``).

Fault tolerance is a claim about every failure, not one rehearsed failure, so runs can be given a
policy that decides, for each component the plan touches, whether it breaks and after how many ticks
of work. A random policy draws that per component from ``Random(f"{seed}/{component}")``: the same
seed breaks the same components at the same moments whatever order the plan invokes them in, so a
failing run can be replayed and a policy can be asked beforehand what it will break.
"""

from __future__ import annotations

import random
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Protocol

from cbrs.actions.errors import ActionsError
from cbrs.actions.plan import Plan


class FaultSpecError(ActionsError, ValueError):
    """A fault policy was given an impossible parameter (a rate outside [0, 1], negative ticks)."""

    def __init__(self, name: str, value: object, why: str) -> None:
        super().__init__(f"{name} = {value!r}: {why}")
        self.name = name
        self.value = value


@dataclass(frozen=True)
class Fault:
    """``component`` breaks once it has worked ``after_ticks`` ticks in this run (0: as it starts)."""

    component: str
    after_ticks: int = 0


class FaultPolicy(Protocol):
    def fault_for(self, component: str) -> Fault | None:
        """The fault ``component`` will suffer in this run, or None."""
        ...


@dataclass(frozen=True)
class FixedFaults:
    """These components fail whenever they are invoked."""

    components: frozenset[str]

    @classmethod
    def of(cls, components: Iterable[str]) -> FixedFaults:
        return cls(frozenset(components))

    def fault_for(self, component: str) -> Fault | None:
        return Fault(component) if component in self.components else None


@dataclass(frozen=True)
class RandomFaults:
    """Each component (of ``among``, if given) breaks with probability ``rate``, once it has done 0 to
    ``max_after_ticks`` ticks of work. The default of 2 suits the simulation, whose components do a
    whole skill per tick: a broken component fails as it first starts, during its first invocation,
    or during its second (a camera that located the robot once and fails the next time)."""

    seed: int
    rate: float
    max_after_ticks: int = 2
    among: frozenset[str] | None = None

    def __post_init__(self) -> None:
        if not 0.0 <= self.rate <= 1.0:
            raise FaultSpecError("rate", self.rate, "a probability must lie in [0, 1]")
        if self.max_after_ticks < 0:
            raise FaultSpecError("max_after_ticks", self.max_after_ticks, "ticks cannot be negative")

    def fault_for(self, component: str) -> Fault | None:
        if self.among is not None and component not in self.among:
            return None
        draw = random.Random(f"{self.seed}/{component}")
        if draw.random() >= self.rate:
            return None
        return Fault(component, draw.randint(0, self.max_after_ticks))


@dataclass(frozen=True)
class Combined:
    """The first fault any of ``policies`` gives (``--fail`` together with ``--fault-rate``)."""

    policies: tuple[FaultPolicy, ...]

    def fault_for(self, component: str) -> Fault | None:
        for policy in self.policies:
            fault = policy.fault_for(component)
            if fault is not None:
                return fault
        return None


def planned_faults(policy: FaultPolicy, plan: Plan) -> list[Fault]:
    """The faults ``policy`` holds for the components ``plan`` may invoke (its choices and alternatives)."""
    components = dict.fromkeys(c for step in plan.steps for c in step.candidates)
    return [fault for fault in map(policy.fault_for, components) if fault is not None]


def doomed_steps(policy: FaultPolicy, plan: Plan) -> list[int]:
    """Steps whose every candidate component has a fault: if those faults strike, no failover can help."""
    return [step.index for step in plan.steps if all(policy.fault_for(c) is not None for c in step.candidates)]
