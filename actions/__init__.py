"""Composition and execution: the action model, the service resource graph, plans, the container.

``Composer(kb).compose("FetchMyPen")`` gives a ``CompositionResult`` with the plan or the needs no
component meets; docs/composition.md explains the algorithm. ``run_task(kb, task, environment)`` runs a
task, as ``cbrs run`` and the server's runs do (they are thin layers over it), and gives a ``RunResult``:
its status, steps, goals and answers (docs/execution.md, "A task run from Python"). The names below load
their modules on first use (the composer brings networkx): a program that only needs, say, a remote
component's error type does not pay for the planner.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from cbrs.actions.composer import (
        ComposeConfig,
        Composer,
        CompositionResult,
        Objective,
        PlanStatus,
        Unsatisfied,
        store_plan,
    )
    from cbrs.actions.errors import ActionsError, OrderingConflictError, UnknownTaskError
    from cbrs.actions.model import ActionClass, ActionLibrary, Ordering, Task, resolve_task
    from cbrs.actions.plan import Binding, Plan, PlanStep, Source
    from cbrs.actions.runner import RunResult, run_task

_HOMES = {
    "cbrs.actions.composer": (
        "ComposeConfig",
        "Composer",
        "CompositionResult",
        "Objective",
        "PlanStatus",
        "Unsatisfied",
        "store_plan",
    ),
    "cbrs.actions.errors": ("ActionsError", "OrderingConflictError", "UnknownTaskError"),
    "cbrs.actions.model": ("ActionClass", "ActionLibrary", "Ordering", "Task", "resolve_task"),
    "cbrs.actions.plan": ("Binding", "Plan", "PlanStep", "Source"),
    "cbrs.actions.runner": ("RunResult", "run_task"),
}
_WHERE = {name: module for module, names in _HOMES.items() for name in names}

__all__ = [
    "ActionClass",
    "ActionLibrary",
    "ActionsError",
    "Binding",
    "ComposeConfig",
    "Composer",
    "CompositionResult",
    "Objective",
    "Ordering",
    "OrderingConflictError",
    "Plan",
    "PlanStatus",
    "PlanStep",
    "RunResult",
    "Source",
    "Task",
    "UnknownTaskError",
    "Unsatisfied",
    "resolve_task",
    "run_task",
    "store_plan",
]


def __getattr__(name: str) -> Any:
    module = _WHERE.get(name)
    if module is None:
        raise AttributeError(f"module 'cbrs.actions' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value
