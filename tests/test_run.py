"""Plans executed in the simulated home: both scenarios, failover, belief state, determinism.

The chosen localiser failing over to the other camera is checked on the run the tasks page starts with
it broken (tests/test_web_act.py), one run for the page's checks and the executor's."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from click.testing import CliRunner

from cbrs.actions.belief import WORLD, BeliefState
from cbrs.actions.composer import Composer
from cbrs.actions.faults import FaultPolicy, RandomFaults, doomed_steps, planned_faults
from cbrs.actions.runner import RunResult, run_task
from cbrs.cli import cli
from cbrs.kb import KnowledgeBase
from cbrs.kb.namespaces import expand
from cbrs.kb.semantic_map import SemanticMap
from cbrs.sim.components import SimEnvironment
from cbrs.sim.world import open_world

SVC = expand("svc:")
HOME = expand("home:")


def run(
    task: str, seed: int = 0, faults: tuple[str, ...] = (), policy: FaultPolicy | None = None
) -> tuple[RunResult, KnowledgeBase, float]:
    kb = KnowledgeBase.open(":memory:")
    with open_world(seed=seed, semantic_map=SemanticMap.read(kb)) as world:
        result = run_task(kb, task, SimEnvironment(world, kb), faults, composer=Composer(kb), fault_policy=policy)
        return result, kb, world.time


@pytest.fixture(scope="module")
def fetch() -> tuple[RunResult, KnowledgeBase, float]:
    return run("FetchMyPen")


def test_fetch_my_pen_succeeds_with_every_effect_verified(fetch: tuple[RunResult, KnowledgeBase, float]) -> None:
    result, _, _ = fetch
    assert result.succeeded, result.report.reason if result.report else result.composition.unsatisfied
    report = result.report
    assert report is not None
    assert all(step.outcome == "succeeded" for step in report.steps)
    checked = [(s.index, ok) for s in report.steps for _, ok in s.effects]
    assert checked and all(ok is True for _, ok in checked)
    deliver = report.steps[-1]
    assert deliver.component == SVC + "DeliverObject_P3DX01"
    assert [str(e[0].predicate) for e in deliver.effects] == [HOME + "isWith"]


def test_the_world_graph_says_the_pen_is_with_the_person(fetch: tuple[RunResult, KnowledgeBase, float]) -> None:
    _, kb, _ = fetch
    belief = BeliefState(kb)
    facts = belief.facts()
    assert (WORLD + "Pen", HOME + "isWith", WORLD + "Person") in facts
    assert (WORLD + "Pen", HOME + "isLocatedOn", WORLD + "KitchenTable") not in facts
    positions = belief.positions()
    pen, person = positions[WORLD + "Pen"], positions[WORLD + "Person"]
    assert abs(pen[0] - person[0]) < 0.6 and abs(pen[1] - person[1]) < 0.6


def test_failure_without_alternative_names_the_step() -> None:
    result, _, _ = run("FetchMyPen", faults=(SVC + "DeliverObject_P3DX01",))
    assert not result.succeeded and result.report is not None
    # it failed at step 15; the plans after it (the pen already delivered to the platform) fail alike
    assert len(result.replans) == 2
    assert "step 15 (DeliverObject_P3DX01) failed with no alternative left" in result.replans[0].reason
    assert "(DeliverObject_P3DX01) failed with no alternative left" in result.report.reason
    assert "DeliverObject_P3DX01: out of order since it failed earlier (InjectedFault" in result.report.reason
    assert result.report.reason.endswith(
        "repair DeliverObject_P3DX01 or register another component that provides (home:Pen, home:isWith, home:Person)"
    )


def chaos_policies(wanted: int, doomed: bool) -> list[RandomFaults]:
    """The first seeded policies (breaking, at random moments, components of FetchMyPen's steps that have
    an alternative) that break something and leave every step a healthy provider, or (``doomed``) that
    break every provider of a step within its first invocation (a simulated component's whole skill
    is one tick), so that the run must fail."""
    kb = KnowledgeBase.open(":memory:")
    plan = Composer(kb).compose("FetchMyPen").plan
    assert plan is not None
    spare = frozenset(c for s in plan.steps if s.alternatives for c in (s.component, *s.alternatives))
    found = []
    for seed in range(200):
        policy = RandomFaults(seed, 0.5, among=spare)
        faults = {f.component: f.after_ticks for f in planned_faults(policy, plan)}
        sure = [i for i in doomed_steps(policy, plan) if all(faults[c] <= 1 for c in plan.step(i).candidates)]
        if faults and (bool(sure) if doomed else not doomed_steps(policy, plan)):
            found.append(policy)
        if len(found) == wanted:
            return found
    raise AssertionError("no such seed below 200")


@pytest.mark.parametrize("policy", chaos_policies(3, doomed=False), ids=lambda p: f"seed{p.seed}")
def test_random_faults_with_a_healthy_alternative_left_never_stop_the_task(policy: RandomFaults) -> None:
    result, _, _ = run("FetchMyPen", policy=policy)
    assert result.succeeded and result.report is not None, result.report.reason if result.report else ""
    assert all(ok is True for s in result.report.steps for _, ok in s.effects)
    for step in result.report.steps:
        failed = [a for a in step.attempts if a.outcome == "failed"]
        assert all("injected failure" in a.reason for a in failed)


@pytest.mark.parametrize("policy", chaos_policies(1, doomed=True), ids=lambda p: f"seed{p.seed}")
def test_random_faults_that_leave_no_provider_name_the_unmet_requirement(policy: RandomFaults) -> None:
    result, _, _ = run("FetchMyPen", policy=policy)
    plan = result.composition.plan
    assert plan is not None and result.report is not None
    assert not result.succeeded
    unmet = result.report.unmet
    assert unmet is not None and unmet.step in doomed_steps(policy, plan)
    assert unmet.requirement == plan.requirement
    assert [a.component for a in unmet.tried] == list(plan.step(unmet.step).candidates)
    assert all("injected failure" in a.reason for a in unmet.tried)
    assert result.report.reason.startswith(f"step {unmet.step} (")
    assert "requirement FetchMyPen not met: no component could provide" in result.report.reason


def test_same_seed_same_outcome(fetch: tuple[RunResult, KnowledgeBase, float]) -> None:
    first, _, first_time = fetch
    again, _, again_time = run("FetchMyPen")
    assert first.report is not None and again.report is not None
    assert again_time == first_time
    durations = [[round(a.seconds, 6) for a in s.attempts] for s in first.report.steps]
    assert durations == [[round(a.seconds, 6) for a in s.attempts] for s in again.report.steps]


def test_cli_run_json_serves_a_cup_and_the_cup_holds_water(tmp_path: Path) -> None:
    """``cbrs run --json --seed`` end to end: the decomposed serving task succeeds with every effect
    verified, and the store it ran on believes the cup below the tap and full. (``--record`` end to end:
    tests/test_recording.py.)"""
    runner = CliRunner()
    store = str(tmp_path / "store")
    done = runner.invoke(cli, ["--store", store, "run", "RobotArmServeACup", "--json", "--seed", "1"])
    assert done.exit_code == 0, done.output
    found = json.loads(done.output)
    assert found["status"] == "succeeded" and found["seed"] == 1
    assert found["plan"]["method"] == "decomposed"
    steps = found["execution"]["steps"]
    assert steps[-1]["component"] == SVC + "FillCupFromTap_CytonDualArm01"
    assert all(effect["verified"] is True for step in steps for effect in step["effects"])
    kb = KnowledgeBase.open(store)
    facts = BeliefState(kb).facts()
    kb.close()
    assert (WORLD + "Cup", HOME + "isLocated", WORLD + "BelowOfTap") in facts
    assert (WORLD + "Cup", HOME + "contains", HOME + "Water") in facts
    bad = runner.invoke(cli, ["--store", store, "run", "FetchMyPen", "--fail", "svc:NoSuchComponent"])
    assert bad.exit_code == 2 and "no simulated component svc:NoSuchComponent" in bad.output
    bad = runner.invoke(cli, ["--store", store, "run", "FetchMyPen", "--record", str(tmp_path / "x.png")])
    assert bad.exit_code == 2 and ".gif" in bad.output


def test_cli_run_with_random_faults_reports_them_and_the_unmet_requirement(tmp_path: Path) -> None:
    runner = CliRunner()
    store = str(tmp_path / "store")
    argv = ["--store", store, "run", "FetchMyPen", "--json", "--fault-rate", "1", "--fault-seed", "5"]
    done = runner.invoke(cli, argv)
    assert done.exit_code == 1, done.output
    found = json.loads(done.output)
    planned = found["random_faults"]["planned"]
    assert found["random_faults"]["seed"] == 5 and found["random_faults"]["rate"] == 1.0
    assert {f["component"] for f in planned} >= {s["component"] for s in found["plan"]["steps"]}
    unmet = found["execution"]["unmet"]
    assert unmet["requirement"] == found["plan"]["requirement"]
    assert unmet["tried"] and all("injected failure" in a["reason"] for a in unmet["tried"])
    text = runner.invoke(cli, argv[:4] + argv[5:])
    assert text.exit_code == 1
    assert "\nrandom faults (seed 5, rate 1.0): " in text.output
    assert "requirement FetchMyPen not met: no component could provide" in text.output
    wrong = runner.invoke(cli, ["--store", store, "run", "FetchMyPen", "--fault-rate", "2"])
    assert wrong.exit_code == 2 and "--fault-rate" in wrong.output
