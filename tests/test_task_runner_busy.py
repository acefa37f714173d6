"""A server's task runner is busy while a run goes, and free as soon as the run's end is said.

The run topic's ``run_finished`` is sent, and the run's ``done`` set, while the run's thread still has a
moment to go; a listener (the page's event stream, the bridge's action, a program) that starts the next run
as it hears the end was refused as "still going" although the run it named read "no-plan". Found by the
example sweep's two-runs-at-once form (docs/benchmarks.md, "Example tasks"). No simulation: the run is one
that no plan can come of.
"""

from __future__ import annotations

import threading
from types import SimpleNamespace
from typing import Any

import pytest

from cbrs import tasks as tasks_module
from cbrs.kb import KnowledgeBase
from cbrs.tasks import TaskBusyError, TaskRunner

WAIT = 10.0


def test_a_run_started_as_the_last_one_ends_is_taken_and_one_started_while_it_goes_is_not(
    bundled_kb: KnowledgeBase, monkeypatch: pytest.MonkeyPatch
) -> None:
    release = threading.Event()

    def no_plan(*_: Any, **__: Any) -> Any:
        release.wait(WAIT)  # the run goes until the test lets it end
        return SimpleNamespace(report=None, to_dict=dict)

    monkeypatch.setattr(tasks_module, "refusal_in_home", no_plan)
    runner = TaskRunner(bundled_kb, threading.RLock(), camera=None)
    heard: list[str] = []

    def listener(topic: str, message: dict[str, Any]) -> None:
        if message.get("event") == "run_finished" and message["run"] == "run-1":
            try:
                heard.append(runner.start("FetchMyPen").id)
            except TaskBusyError as error:
                heard.append(f"refused: {error}")

    runner.subscribe(listener)
    first = runner.start("FetchMyPen")
    with pytest.raises(TaskBusyError):
        runner.start("FetchMyPen")  # while the first goes
    assert runner.active() is first
    release.set()
    assert first.done.wait(WAIT) and first.status == "no-plan"
    assert heard == ["run-2"]
    second = runner.get("run-2")
    assert second is not None and second.done.wait(WAIT) and second.status == "no-plan"
    assert runner.active() is None
