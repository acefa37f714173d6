"""Composition (and, next, execution): the action model, the service resource graph, plans.

``Composer(kb).compose("FetchMyPen")`` gives a ``CompositionResult`` with the plan or the needs no
component meets; docs/composition.md explains the algorithm.
"""

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
    "Source",
    "Task",
    "UnknownTaskError",
    "Unsatisfied",
    "resolve_task",
    "store_plan",
]
