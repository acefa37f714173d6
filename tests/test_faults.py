"""Injected faults, fixed and seeded-random, against the executor's failover (stub components)."""

from __future__ import annotations

import pytest

from cbrs.actions.components import Container, Registry
from cbrs.actions.executor import Executor, RunStatus
from cbrs.actions.faults import Combined, Fault, FaultSpecError, FixedFaults, RandomFaults, doomed_steps, planned_faults
from cbrs.actions.plan import Plan, Source
from tests.test_execution import EX, Stub, plan, step

COMPONENTS = ("Map", "Cam1", "Cam2", "Plan1", "Plan2", "Drive", "Arm")


def patrol() -> Plan:
    """Seven steps; the localiser and the planner have alternatives, and both are used twice."""
    return plan(
        step(1, "Map", Source("given", None, EX + "Req")),
        step(2, "Cam1", Source("out", 1), ("Cam2",)),
        step(3, "Plan1", Source("out", 2), ("Plan2",)),
        step(4, "Drive", Source("out", 3)),
        step(5, "Cam1", Source("out", 4), ("Cam2",)),
        step(6, "Plan1", Source("out", 5), ("Plan2",)),
        step(7, "Arm", Source("out", 6)),
    )


def execute(target: Plan, policy: RandomFaults | FixedFaults | Combined) -> tuple[Executor, dict[str, Stub]]:
    stubs = {name: Stub(EX + name, ticks=3) for name in COMPONENTS}
    registry = Registry()
    for name, stub in stubs.items():
        registry.add(EX + name, lambda iri, stub=stub: stub)
    executor = Executor(target, Container(registry, faults=policy), {"given": "g"})
    executor.run(max_ticks=1000)
    return executor, stubs


def test_random_faults_are_a_function_of_seed_and_component() -> None:
    names = [EX + n for n in COMPONENTS]
    first = [RandomFaults(7, 0.5).fault_for(n) for n in names]
    again = [RandomFaults(7, 0.5).fault_for(n) for n in reversed(names)]
    assert first == list(reversed(again))  # the order of asking changes nothing
    drawn = {tuple(RandomFaults(seed, 0.5).fault_for(n) for n in names) for seed in range(20)}
    assert len(drawn) > 10  # other seeds break other components
    assert all(RandomFaults(s, 0.0).fault_for(n) is None for s in range(20) for n in names)
    always = [RandomFaults(s, 1.0, max_after_ticks=3).fault_for(n) for s in range(20) for n in names]
    assert all(f is not None and 0 <= f.after_ticks <= 3 for f in always)
    only = RandomFaults(1, 1.0, among=frozenset({EX + "Cam1"}))
    assert only.fault_for(EX + "Cam2") is None and only.fault_for(EX + "Cam1") is not None


@pytest.mark.parametrize(("name", "kwargs"), [("rate", {"rate": 1.5}), ("max_after_ticks", {"max_after_ticks": -1})])
def test_an_impossible_policy_is_refused_naming_the_parameter(name: str, kwargs: dict[str, float]) -> None:
    arguments: dict[str, float] = {"rate": 0.5, **kwargs}
    with pytest.raises(FaultSpecError, match=name) as raised:
        RandomFaults(1, **arguments)  # type: ignore[arg-type]
    assert raised.value.name == name


def test_a_fault_can_strike_in_the_middle_of_an_invocation() -> None:
    executor, stubs = execute(patrol(), FixedFaults.of(()))
    assert executor.status is RunStatus.SUCCEEDED
    executor, stubs = execute(patrol(), Combined((RandomFaults(0, 0.0), _Exactly(EX + "Cam1", 4))))
    report = executor.report()
    assert report.status is RunStatus.SUCCEEDED
    # Cam1 works 3 ticks for step 2, then breaks on its second tick of step 5 and is halted there.
    assert [a.outcome for a in report.steps[1].attempts] == ["succeeded"]
    assert [(a.component, a.outcome) for a in report.steps[4].attempts] == [
        (EX + "Cam1", "failed"),
        (EX + "Cam2", "succeeded"),
    ]
    assert "after 4 ticks of work" in report.steps[4].attempts[0].reason
    assert stubs["Cam1"].halted == 1
    assert stubs["Plan1"].seen[-1] == {"in": "Cam2(Drive(Plan1(Cam1(Map(g)))))"}


class _Exactly:
    """One component breaks after a given amount of work."""

    def __init__(self, component: str, after_ticks: int) -> None:
        self.fault = Fault(component, after_ticks)

    def fault_for(self, component: str) -> Fault | None:
        return self.fault if component == self.fault.component else None


def test_seeded_chaos_every_run_with_an_alternative_succeeds_the_others_name_the_unmet_need() -> None:
    target = patrol()
    outcomes = {"survived": 0, "failed over": 0, "failed": 0}
    for seed in range(150):
        policy = RandomFaults(seed, 0.35)
        doomed = doomed_steps(policy, target)
        executor, _ = execute(target, policy)
        report = executor.report()
        if not doomed:
            assert report.status is RunStatus.SUCCEEDED, (seed, report.reason)
        if report.status is RunStatus.SUCCEEDED:
            broken = [a for s in report.steps for a in s.attempts if a.outcome == "failed"]
            assert all("injected failure" in a.reason for a in broken), seed
            outcomes["failed over" if broken else "survived"] += 1
            continue
        outcomes["failed"] += 1
        unmet = report.unmet
        assert unmet is not None, seed
        assert unmet.step in doomed, (seed, unmet.step, doomed)  # only a step without a healthy provider fails
        candidates = {target.step(unmet.step).component, *target.step(unmet.step).alternatives}
        assert {a.component for a in unmet.tried} <= candidates
        assert all(a.outcome == "failed" and "injected failure" in a.reason for a in unmet.tried)
        expected_needs = [f"step {unmet.step + 1}"] if unmet.step < len(target.steps) else []
        assert list(unmet.needed_by) == expected_needs
        assert report.reason.startswith(f"step {unmet.step} (")
        assert "failed with no alternative left; requirement Req not met: no component could provide" in report.reason
        assert report.to_dict()["unmet"]["step"] == unmet.step
    # the seeds exercise every outcome, so none of the checks above is vacuous
    assert all(count > 0 for count in outcomes.values()), outcomes


def test_planned_faults_cover_the_plan_components_and_their_alternatives() -> None:
    target = patrol()
    policy = RandomFaults(3, 1.0)
    assert sorted(f.component for f in planned_faults(policy, target)) == sorted(EX + c for c in COMPONENTS)
    assert doomed_steps(policy, target) == [1, 2, 3, 4, 5, 6, 7]
    assert doomed_steps(RandomFaults(3, 1.0, among=frozenset({EX + "Cam1", EX + "Drive"})), target) == [4]
