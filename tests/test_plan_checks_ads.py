"""The plan checks of ``SimEnvironment.given`` work from the advertisements the environment read to make its
components (at its start and at each refresh) instead of reading them all again (20-30 ms a plan on the
bundled store): they see every advertisement the store has, refuse as before, and a refresh gives them what
was registered since. One world is built and not stepped (the lab5 home of two people in one shirt colour,
seed 1, refused before anything moves)."""

from __future__ import annotations

from typing import Any

import pytest

from cbrs.actions.composer import Composer
from cbrs.kb import KnowledgeBase
from cbrs.kb.person_choice import LookAlikePeopleError
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim import run_checks
from cbrs.sim.components import SimEnvironment
from cbrs.sim.world import open_world
from tests.helpers_examples import lab5_store as _store


def _counting(kb: KnowledgeBase, monkeypatch: pytest.MonkeyPatch) -> list[int]:
    """Count the store's reads of every advertisement from now on."""
    reads = [0]
    original = kb.advertisements

    def counted(*args: Any, **kwargs: Any) -> Any:
        reads[0] += 1
        return original(*args, **kwargs)

    monkeypatch.setattr(kb, "advertisements", counted)
    return reads


def test_the_plan_checks_refuse_as_before_from_the_environments_advertisements(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    kb = _store(things=("lab5_visitor_in_yellow.ttl",))
    plan = Composer(kb).compose("FetchMyPen").plan
    assert plan is not None
    requirements = {requirement.iri: requirement for requirement in kb.requirements()}
    with open_world(seed=1, semantic_map=SemanticMap.read(kb)) as world:
        environment = SimEnvironment(world, kb)
        assert set(environment.advertisements) == {ad.iri for ad in kb.advertisements()}
        environment.perceive()
        reads = _counting(kb, monkeypatch)
        seen: list[Any] = []
        base_for = run_checks.base_for

        def seeing(world: Any, plan: Any, ads: Any, values: Any) -> Any:
            seen.append(ads)  # what the checks work from (the first of them, before the people)
            return base_for(world, plan, ads, values)

        monkeypatch.setattr(run_checks, "base_for", seeing)
        start = world.time
        with pytest.raises(LookAlikePeopleError, match="as Visitor1 does") as refused:
            environment.given(plan, requirements)
        assert refused.value.step.endswith("TrackPerson_CeilingCamera01")
        assert reads == [0]  # the environment's read, not another
        assert seen == [environment.advertisements]
        assert world.time == start

        tracker = next(iri for iri in environment.advertisements if iri.endswith("TrackPerson_CeilingCamera01"))
        kept = environment.advertisements.pop(tracker)  # as if registered after the environment read them
        environment.refresh()
        assert reads == [1]
        assert environment.advertisements[tracker] == kept
        with pytest.raises(LookAlikePeopleError):
            environment.given(plan, requirements)
