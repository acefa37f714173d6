"""The run page says how the task's own preconditions stood before its first step, in the line ``cbrs run``
prints under its verdict (``cbrs.tasks.preconditions_line``; docs/execution.md, "A task's preconditions"):
those taken as given named, those perceived holding counted; a run without any says nothing of them.
A runner whose runs end at once with a given result: no planner, no world."""

from __future__ import annotations

from html import unescape
from typing import Any

import pytest
from flask.testing import FlaskClient

from cbrs.kb import KnowledgeBase
from cbrs.sparql_service import SparqlService
from cbrs.tasks import PRECONDITIONS_NAMED, TaskRun, TaskRunner, preconditions_line
from cbrs.web import create_app

MARKER = "(home:MobileRobot, home:hasMarker, home:ColourMarker)"


class _Given(TaskRunner):
    """A runner whose runs succeed at once with ``self.checks`` as the result's preconditions."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.checks: list[dict[str, Any]] = []

    def _run(self, run: TaskRun) -> None:
        run.result = {"plan": {"status": "planned"}, "execution": {"status": "succeeded", "steps": []}}
        if self.checks:
            run.result["preconditions"] = self.checks
        run.status = "succeeded"
        run.done.set()


@pytest.fixture(scope="module")
def served(bundled_kb: KnowledgeBase) -> tuple[FlaskClient, _Given]:
    sparql = SparqlService(bundled_kb)
    runner = _Given(bundled_kb, sparql.lock, camera=None)
    return create_app(sparql, tasks=runner).test_client(), runner


def _shown(served: tuple[FlaskClient, _Given], checks: list[dict[str, Any]]) -> tuple[str, dict[str, Any]]:
    client, runner = served
    runner.checks = checks
    run = runner.run("FetchMyPen", timeout=10.0)
    page = client.get(f"/tasks/{run.id}")
    twin = client.get(f"/tasks/{run.id}.json")
    assert page.status_code == twin.status_code == 200
    return " ".join(unescape(page.text).split()), twin.get_json()["run"]


def test_the_run_page_names_a_precondition_taken_as_given(served: tuple[FlaskClient, _Given]) -> None:
    text, run = _shown(served, [{"statement": MARKER, "believed": None}])
    line = f"Preconditions: 1 taken as given, no test decides it: {MARKER}"
    assert line in text and run["preconditions_line"] == line
    assert line[1:] == preconditions_line(run["result"]["preconditions"])[1:]  # cbrs run's words


def test_held_ones_are_counted_and_the_rest_beyond_the_bound_left_to_the_json(
    served: tuple[FlaskClient, _Given],
) -> None:
    given = [
        {"statement": f"(lab:Thing{n}, lab:on, lab:Tray)", "believed": None} for n in range(PRECONDITIONS_NAMED + 1)
    ]
    text, run = _shown(served, [{"statement": MARKER, "believed": True}, *given])
    assert f"Preconditions: 1 perceived holding; {len(given)} taken as given, no test decides them:" in text
    assert "and 1 more (the run's JSON lists each)" in text and given[-1]["statement"] not in text
    assert len(run["result"]["preconditions"]) == len(given) + 1  # where the rest are


def test_a_run_without_preconditions_says_nothing_of_them(served: tuple[FlaskClient, _Given]) -> None:
    text, run = _shown(served, [])
    assert "Preconditions:" not in text and run["preconditions_line"] == ""
