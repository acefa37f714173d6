"""Atomic components and the container that manages their lifecycle (paper sections 2.1 and 5).

A component implements one advertised service. The container creates it on first use, hands it its
resources (``initialise``), runs invocations (``begin`` then ``update`` tick by tick), and moves it
through a fixed lifecycle; an illegal transition is a bug and raises ``LifecycleError``.

    created -> initialised -> running <-> suspended -> stopped -> (running again) ... -> finalised
                                  \\-------------------> error ---------------------------^

Components are tested tick by tick with stubs; no simulator is needed (tests/test_execution.py).
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from enum import Enum
from typing import Any

from cbrs.actions.errors import ActionsError
from cbrs.actions.events import EventBus, Priority
from cbrs.actions.faults import Fault, FaultPolicy


class Status(Enum):
    """What one tick of a component's invocation says."""

    RUNNING = "running"
    SUCCEEDED = "succeeded"
    FAILED = "failed"


class LifecycleState(Enum):
    CREATED = "created"
    INITIALISED = "initialised"
    RUNNING = "running"
    SUSPENDED = "suspended"
    STOPPED = "stopped"
    ERROR = "error"
    FINALISED = "finalised"


_ALLOWED: dict[LifecycleState, frozenset[LifecycleState]] = {
    LifecycleState.CREATED: frozenset({LifecycleState.INITIALISED, LifecycleState.ERROR, LifecycleState.FINALISED}),
    LifecycleState.INITIALISED: frozenset({LifecycleState.RUNNING, LifecycleState.ERROR, LifecycleState.FINALISED}),
    LifecycleState.RUNNING: frozenset({LifecycleState.SUSPENDED, LifecycleState.STOPPED, LifecycleState.ERROR}),
    LifecycleState.SUSPENDED: frozenset({LifecycleState.RUNNING, LifecycleState.STOPPED, LifecycleState.ERROR}),
    LifecycleState.STOPPED: frozenset({LifecycleState.RUNNING, LifecycleState.ERROR, LifecycleState.FINALISED}),
    LifecycleState.ERROR: frozenset({LifecycleState.FINALISED}),
    LifecycleState.FINALISED: frozenset(),
}


class LifecycleError(ActionsError):
    """A component was asked for a transition its lifecycle does not allow."""

    def __init__(self, component: str, current: LifecycleState, wanted: LifecycleState) -> None:
        self.component = component
        self.current = current
        self.wanted = wanted
        super().__init__(f"component {component}: cannot go from {current.value} to {wanted.value}")


class NoImplementationError(ActionsError):
    """The plan uses a component no implementation is registered for."""

    http_status = 501

    def __init__(self, component: str) -> None:
        self.component = component
        super().__init__(f"no implementation for component {component}")


def _not_asked() -> bool:
    return False


class InjectedFault(RuntimeError):
    """Raised inside a component whose failure was injected (``--fail``)."""


class Component(ABC):
    """One advertised service, implemented. Subclasses override ``begin`` and ``update``."""

    def __init__(self, iri: str) -> None:
        self.iri = iri
        self.outputs: dict[str, Any] = {}
        self.reason = ""  # why the last invocation failed
        self.stop_asked: Callable[[], bool] = _not_asked
        """Whether the run was asked to stop (set by the container that starts an invocation): a component
        whose tick waits long on another process looks between short waits, so a Stop need not wait out the
        tick, and :meth:`halt` knows the run was stopped rather than timed out."""

    def initialise(self, context: Any) -> None:
        """Take the resources the component needs (a simulated world, a knowledge base)."""
        return None

    @abstractmethod
    def begin(self, inputs: Mapping[str, Any]) -> None:
        """Start one invocation with its inputs (by parameter name)."""

    @abstractmethod
    def update(self) -> Status:
        """Advance the invocation by one tick."""

    def halt(self) -> None:
        """Stop an invocation that is still running (on timeout or failover)."""
        return None

    def waiting(self) -> bool:
        """Whether the invocation under way only waits on another process now (its call is out, unanswered):
        a Stop then ends it at once (:meth:`halt`) instead of letting it end, since nothing in this process
        is half done (docs/execution.md, "Stop"). A simulated motion is let end."""
        return False

    def finalise(self) -> None:
        """Release what ``initialise`` took."""
        return None


@dataclass
class Managed:
    component: Component
    state: LifecycleState = LifecycleState.CREATED
    fault: Fault | None = None  # an injected fault: invocations raise once it has worked fault.after_ticks
    worked: int = 0  # ticks of work over every invocation in this run
    history: list[LifecycleState] = field(default_factory=lambda: [LifecycleState.CREATED])


class Container:
    """Creates, runs and retires components; publishes every lifecycle change on the event bus."""

    def __init__(
        self,
        factory: Callable[[str], Component],
        context: Any = None,
        bus: EventBus | None = None,
        faults: FaultPolicy | None = None,
        stopping: Callable[[], bool] | None = None,
    ) -> None:
        self._factory = factory
        self._context = context
        self._stopping = stopping  # whether the run was asked to stop: each invocation started is told
        self.bus = bus or EventBus()
        self._managed: dict[str, Managed] = {}
        self._policy = faults
        self._faults: dict[str, Fault] = {}

    def inject_fault(self, iri: str, after_ticks: int = 0) -> None:
        """Make ``iri`` fail once it has worked ``after_ticks`` ticks (0: every invocation fails)."""
        fault = Fault(iri, after_ticks)
        self._faults[iri] = fault
        if iri in self._managed:
            self._managed[iri].fault = fault

    def fault_for(self, iri: str) -> Fault | None:
        """The fault ``iri`` suffers in this run: injected by hand, else the policy's, else None."""
        if iri in self._faults:
            return self._faults[iri]
        return self._policy.fault_for(iri) if self._policy is not None else None

    def state(self, iri: str) -> LifecycleState:
        return self._managed[iri].state if iri in self._managed else LifecycleState.CREATED

    def reason(self, iri: str) -> str:
        """Why ``iri``'s last invocation went wrong (empty if it did not, or never ran)."""
        return self._managed[iri].component.reason if iri in self._managed else ""

    def history(self, iri: str) -> list[LifecycleState]:
        return list(self._managed[iri].history) if iri in self._managed else []

    def component(self, iri: str) -> Component:
        """The component for ``iri``, created and initialised on first use."""
        if iri not in self._managed:
            managed = Managed(self._factory(iri), fault=self.fault_for(iri))
            self._managed[iri] = managed
            self._publish(iri, LifecycleState.CREATED)
            try:
                managed.component.initialise(self._context)
            except Exception as error:
                managed.component.reason = f"initialise failed: {error}"
                self._move(iri, LifecycleState.ERROR)
                raise
            self._move(iri, LifecycleState.INITIALISED)
        return self._managed[iri].component

    def start(self, iri: str, inputs: Mapping[str, Any]) -> None:
        component = self.component(iri)
        self._move(iri, LifecycleState.RUNNING)
        component.outputs = {}
        component.reason = ""
        if self._stopping is not None:
            component.stop_asked = self._stopping
        self._check_fault(self._managed[iri])
        component.begin(inputs)

    def tick(self, iri: str) -> Status:
        managed = self._managed[iri]
        if managed.state is LifecycleState.SUSPENDED:
            return Status.RUNNING
        managed.worked += 1
        self._check_fault(managed)
        status = managed.component.update()
        if status is not Status.RUNNING:
            self._move(iri, LifecycleState.STOPPED)
        return status

    def suspend(self, iri: str) -> None:
        self._move(iri, LifecycleState.SUSPENDED)

    def resume(self, iri: str) -> None:
        self._move(iri, LifecycleState.RUNNING)

    def abort(self, iri: str, reason: str) -> None:
        """An invocation went wrong: halt it and put the component in the error state."""
        managed = self._managed.get(iri)
        if managed is None or managed.state in (LifecycleState.ERROR, LifecycleState.FINALISED):
            return
        if managed.state in (LifecycleState.RUNNING, LifecycleState.SUSPENDED):
            managed.component.halt()
        managed.component.reason = reason
        self._move(iri, LifecycleState.ERROR)

    def recover(self) -> list[str]:
        """Give a fresh instance to every component in the error state whose fault has not struck: a
        skill that failed because the world was not as expected may succeed in a new plan, while a
        broken one (its fault fired) stays broken. Returns the components recovered."""
        recovered = []
        for iri, managed in list(self._managed.items()):
            fault = managed.fault
            if managed.state is not LifecycleState.ERROR or (fault is not None and managed.worked >= fault.after_ticks):
                continue
            managed.component.finalise()
            self._move(iri, LifecycleState.FINALISED)
            del self._managed[iri]
            try:
                self.component(iri)
            except Exception:  # it cannot even start again: it stays in the error state
                continue
            self._managed[iri].worked = managed.worked  # a fault due later still comes when it is due
            recovered.append(iri)
        return recovered

    def finalise_all(self) -> None:
        for iri, managed in self._managed.items():
            if managed.state in (LifecycleState.RUNNING, LifecycleState.SUSPENDED):
                managed.component.halt()
                self._move(iri, LifecycleState.STOPPED)
            if managed.state is not LifecycleState.FINALISED:
                managed.component.finalise()
                self._move(iri, LifecycleState.FINALISED)

    @staticmethod
    def _check_fault(managed: Managed) -> None:
        fault = managed.fault
        if fault is not None and managed.worked >= fault.after_ticks:
            when = f" after {fault.after_ticks} ticks of work" if fault.after_ticks else ""
            raise InjectedFault(f"injected failure of {managed.component.iri}{when}")

    def _move(self, iri: str, wanted: LifecycleState) -> None:
        managed = self._managed[iri]
        if wanted not in _ALLOWED[managed.state]:
            raise LifecycleError(iri, managed.state, wanted)
        managed.state = wanted
        managed.history.append(wanted)
        self._publish(iri, wanted)

    def _publish(self, iri: str, state: LifecycleState) -> None:
        priority = Priority.HIGH if state is LifecycleState.ERROR else Priority.NORMAL
        self.bus.publish("/cbrs/lifecycle", {"component": iri, "state": state.value}, priority)


class Registry:
    """Component implementations by service IRI: what a container's factory looks up."""

    def __init__(self) -> None:
        self._makers: dict[str, Callable[[str], Component]] = {}

    def add(self, iri: str, maker: Callable[[str], Component]) -> None:
        self._makers[iri] = maker

    def __contains__(self, iri: object) -> bool:
        return iri in self._makers

    def names(self) -> list[str]:
        """The IRIs of the components this registry can make."""
        return sorted(self._makers)

    def __call__(self, iri: str) -> Component:
        maker = self._makers.get(iri)
        if maker is None:
            raise NoImplementationError(iri)
        return maker(iri)
