"""The ceiling cameras as programs of their own: one is killed mid-run and the task still succeeds."""

from __future__ import annotations

import os

from cbrs.external_demo import run_external_demo
from cbrs.kb.namespaces import PREFIXES

SVC = PREFIXES["svc"]


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    return True


def test_a_camera_killed_mid_run_is_noticed_within_two_leases_and_the_run_finishes_on_the_other() -> None:
    said: list[str] = []
    run = run_external_demo(seed=0, kill="CeilingCamera01", lease=1.0, say=said.append)
    assert run.result is not None and run.result.succeeded, run.result
    assert run.killed == "CeilingCamera01"
    assert run.detected_after is not None and run.detected_after <= 2 * run.lease
    report = run.result.report
    assert report is not None
    located = [step for step in report.steps if "LocateMobileRobot" in step.planned]
    first = [(attempt.component, attempt.outcome) for attempt in located[0].attempts]
    assert first == [
        (SVC + "LocateMobileRobot_CeilingCamera01", "failed"),
        (SVC + "LocateMobileRobot_CeilingCamera02", "succeeded"),
    ]
    assert all(step.outcome == "succeeded" for step in located)
    assert not any(_alive(pid) for pid in run.pids.values())  # both programs stopped by their PID
    assert any("killed CeilingCamera01" in line for line in said)
