"""A task with no plan because the one component that provides its goal is a live component unavailable
now (its program stopped, its lease lapsed) names that component and why (actions/unavailable.py): the store
leaves it out of composition, so the answer was "no component provides ...; register a component whose
effect is ...", to a user who had registered one."""

from __future__ import annotations

from pathlib import Path

from cbrs.actions.composer import ComposeConfig, Composer
from cbrs.actions.unavailable import name_unavailable
from tests.test_composition import EX
from tests.test_progression_joined import PREFIXES, _component, _condition, _parameter, _requirement, _store

SERVICES = (
    PREFIXES
    + _component("PutAway", " ; ".join([_parameter("obj", "Obj"), _condition("Effect", "Obj", "at", "Shelf")]))
    + _requirement("Req", {"obj": "Obj"}, [("Obj", "at", "Shelf")])
)


def test_a_lapsed_live_component_a_plan_would_use_is_named_with_why(tmp_path: Path) -> None:
    kb = _store(tmp_path, SERVICES, reachieve=False)
    kb.liveness.renew(EX + "PutAway", 600.0)
    assert Composer(kb).compose(EX + "Req", belief=True).plan is not None  # live: planned
    kb.liveness.expire(EX + "PutAway", "its lease lapsed")
    composition = Composer(kb).compose(EX + "Req", belief=True)
    assert composition.plan is None and composition.unsatisfied
    named = name_unavailable(kb, ComposeConfig(), EX + "Req", composition, frozenset(), belief=True)
    assert named.plan is None
    for unmet in named.unsatisfied:
        assert unmet.unrunnable == ((EX + "PutAway", "unavailable: its lease lapsed"),)
        assert "PutAway was planned for it but cannot run here: unavailable: its lease lapsed" in unmet.text()


def test_a_component_the_run_avoids_is_not_named_as_unavailable(tmp_path: Path) -> None:
    kb = _store(tmp_path, SERVICES, reachieve=False)
    kb.liveness.renew(EX + "PutAway", 600.0)
    kb.liveness.expire(EX + "PutAway", "its lease lapsed")
    composition = Composer(kb).compose(EX + "Req", belief=True)
    avoided = name_unavailable(kb, ComposeConfig(), EX + "Req", composition, frozenset({EX + "PutAway"}), belief=True)
    assert avoided is composition  # a component the run chose to avoid is its own reason, said elsewhere
