"""Cancelling a run between steps (what the /cbrs/run_task action's cancel does), tick by tick with stubs."""

from __future__ import annotations

from cbrs.actions.components import LifecycleState
from cbrs.actions.executor import Executor, RunStatus
from tests.test_execution import EX, Stub, chain, setup


def test_cancel_between_steps_stops_the_run_and_starts_nothing_more() -> None:
    stubs = {n: Stub(EX + n) for n in "ABC"}
    container = setup(stubs)
    heard: list[dict[str, object]] = []
    container.bus.subscribe("/cbrs/task", lambda event: heard.append(event.message))
    executor = Executor(chain(), container, {"given": "g"})
    while len(executor.results) < 1:
        executor.tick()
    executor.cancel("cancelled on request after 1 of 3 steps")
    assert executor.tick() is RunStatus.CANCELLED
    report = executor.report()
    assert (report.status, report.reason) == (RunStatus.CANCELLED, "cancelled on request after 1 of 3 steps")
    assert [s.outcome for s in report.steps] == ["succeeded", "pending", "pending"]
    assert stubs["B"].seen == [] and container.state(EX + "B") is LifecycleState.CREATED
    assert heard[-1]["status"] == "cancelled"
    assert report.to_dict()["status"] == "cancelled"


def test_cancel_mid_step_aborts_the_component_and_a_finished_run_stays_as_it_ended() -> None:
    stubs = {n: Stub(EX + n, ticks=5) for n in "ABC"}
    container = setup(stubs)
    executor = Executor(chain(), container, {"given": "g"})
    executor.tick()  # A starts
    executor.cancel("stop")
    assert executor.status is RunStatus.CANCELLED
    assert container.state(EX + "A") is not LifecycleState.RUNNING
    done = Executor(chain(), setup({n: Stub(EX + n) for n in "ABC"}), {"given": "g"})
    done.run(100)
    done.cancel("too late")
    assert (done.status, done.reason) == (RunStatus.SUCCEEDED, "")
