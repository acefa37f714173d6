"""A task that asks for an output (a room's temperature) gets the value back: ``RunResult.answers``, its
``to_dict`` (``cbrs run --json``, the bridge's and the browser's run), ``cbrs run``'s text and the run
page. Stub thermometers answer through a transport of the test's: no simulation, no server."""

from __future__ import annotations

import json
from collections.abc import Mapping
from concurrent.futures import Future
from dataclasses import replace
from typing import Any

import pytest
from markupsafe import escape

from cbrs.actions.composer import Composer
from cbrs.actions.executor import ExecutionReport, RunStatus, StepReport
from cbrs.actions.runner import Answer, GoalCheck, RunResult, run_task
from cbrs.cli_actions import run_text
from cbrs.kb import KnowledgeBase, Statement
from cbrs.kb.namespaces import HOME
from cbrs.sparql_service import SparqlService
from cbrs.tasks import TaskRun, TaskRunner
from cbrs.web import create_app
from tests.test_live_components import REQ
from tests.test_remote_breaker import FIRST, READING, SECOND, Room, lab_kb

__all__ = ["lab_kb"]  # the two thermometers' store, a module fixture of its own here too

TEMPERATURE = HOME + "RoomTemperature"


class Answering:
    """A transport whose services answer at once: ``answers`` by service, a reading by default; an
    exception in it fails the call."""

    def __init__(self, answers: Mapping[str, Any] | None = None) -> None:
        self.answers = dict(answers or {})

    def call(self, service: str, args: Mapping[str, Any], timeout: float) -> Future[dict[str, Any]]:
        future: Future[dict[str, Any]] = Future()
        answer = self.answers.get(service, READING)
        if isinstance(answer, Exception):
            future.set_exception(answer)
        else:
            future.set_result(answer)
        return future


def _run(kb: KnowledgeBase, transport: Answering, max_replans: int = 2) -> RunResult:
    return run_task(kb, REQ + "RoomTemperature", Room(kb, transport), composer=Composer(kb), max_replans=max_replans)


def test_the_temperature_a_thermometer_read_is_the_run_s_answer(lab_kb: KnowledgeBase) -> None:
    result = _run(lab_kb, Answering())
    assert result.succeeded
    (answer,) = result.answers
    assert (answer.name, answer.concept, answer.step, answer.component) == ("roomTemperature", TEMPERATURE, 1, FIRST)
    assert answer.value == {"@type": TEMPERATURE, "celsius": 21.5}  # as checked: its class written in full
    found = result.to_dict()
    assert found["answers"] == [
        {
            "name": "roomTemperature",
            "class": TEMPERATURE,
            "value": {"@type": TEMPERATURE, "celsius": 21.5},
            "step": 1,
            "component": FIRST,
            "output": "roomTemperature",
            "text": 'roomTemperature (home:RoomTemperature) = {"celsius": 21.5}'
            " from svc:ReadRoomTemperature_Thermometer31 (step 1)",
        }
    ]
    assert list(found)[:-1] == ["task", "status", "plan", "execution", "replans", "goals"]  # as before, in order


def test_cbrs_run_prints_the_answer_after_its_verdict(lab_kb: KnowledgeBase) -> None:
    text = run_text(_run(lab_kb, Answering()), 0.0, 0.0)
    verdict, heading, line = text.splitlines()[-3:]
    assert verdict.startswith("req:RoomTemperature: succeeded")
    assert heading == "Answer:"
    assert (
        line
        == '  roomTemperature (home:RoomTemperature) = {"celsius": 21.5} from svc:' + FIRST.split("#")[1] + " (step 1)"
    )


def test_after_a_failover_the_answer_names_the_component_that_gave_it(lab_kb: KnowledgeBase) -> None:
    transport = Answering({"/thermometer31/read": RuntimeError("the sensor is unplugged")})
    result = _run(lab_kb, transport)
    assert result.succeeded and result.report is not None and result.report.steps[0].failed_over
    (answer,) = result.answers
    assert answer.component == SECOND and answer.text().endswith("from svc:ReadRoomTemperature_Thermometer32 (step 1)")


def test_a_bare_number_fails_the_step_saying_the_whole_value_is_wrong_and_the_run_answers_nothing(
    lab_kb: KnowledgeBase,
) -> None:
    bare = {"roomTemperature": 21.5}
    result = _run(lab_kb, Answering({"/thermometer31/read": bare, "/thermometer32/read": bare}), max_replans=0)
    assert not result.succeeded and result.report is not None
    reason = result.report.steps[0].attempts[0].reason
    assert "malformed home:RoomTemperature: the whole value is 21.5, expected a JSON object" in reason
    assert "(value)" not in reason
    assert result.answers == () and result.to_dict()["answers"] == []
    assert "Answer" not in run_text(result, 0.0, 0.0)


@pytest.mark.parametrize(
    ("answer", "expected"),
    [
        pytest.param(
            Answer("where", HOME + "RobotPosition", {"@type": HOME + "RobotLocation", "x": 1.23456}, 2, FIRST, "at"),
            'where (home:RobotPosition) = {"@type": "home:RobotLocation", "x": 1.235} from svc:',
            id="another-class-prefixed-numbers-rounded",
        ),
        pytest.param(
            Answer("t", TEMPERATURE, None, 1, FIRST, "roomTemperature"),
            "t (home:RoomTemperature): no value; svc:ReadRoomTemperature_Thermometer31 gave none named"
            " 'roomTemperature' (step 1)",
            id="missing",
        ),
        pytest.param(Answer("n", None, 21.5, 1, FIRST, "n"), "n = 21.5 from svc:", id="no-class-bare-number"),
        pytest.param(Answer("o", None, object, 1, FIRST, "o"), "o = \"<class 'object'>\" from", id="not-json"),
    ],
)
def test_an_answer_reads_as_one_line(answer: Answer, expected: str) -> None:
    assert answer.text().startswith(expected)


def test_a_long_value_is_cut_in_the_text_and_kept_whole_in_the_json() -> None:
    grid = {"@type": HOME + "OccupancyGridMap", "cells": "A" * 5000}
    answer = Answer("map", HOME + "OccupancyGridMap", grid, 1, FIRST, "map")
    shown = answer.text()
    whole = len(json.dumps({"cells": grid["cells"]}))
    assert len(shown) < 300 and f"\u2026 ({whole} characters in all) from svc:" in shown
    assert answer.to_dict()["value"] == grid


def test_the_run_page_shows_the_answer(lab_kb: KnowledgeBase) -> None:
    result = _run(lab_kb, Answering())
    sparql = SparqlService(lab_kb)
    runner = TaskRunner(lab_kb, sparql.lock, camera=None)
    done = TaskRun("run-1", "RoomTemperature", 0, (), iri=REQ + "RoomTemperature", status="succeeded")
    done.result = {**result.to_dict(), "sim_seconds": 0.0}
    runner._runs[done.id] = done  # a finished run, as a run in the home leaves it
    client = create_app(sparql, tasks=runner).test_client()
    page = client.get("/tasks/run-1").text
    assert "<h3>Answer " in page and str(escape(result.answers[0].text())) in page
    twin = client.get("/tasks/run-1.json").get_json()
    assert twin["run"]["result"]["answers"][0]["value"] == {"@type": TEMPERATURE, "celsius": 21.5}


@pytest.mark.parametrize(
    ("task", "answered"),
    [
        pytest.param("RobotSelfPosition", ["selfPosition"], id="its-own-output"),
        pytest.param("RobotArmServeACup", [], id="a-sub-action-s-output-is-no-answer"),
    ],
)
def test_only_the_task_s_own_outputs_are_answers(bundled_kb: KnowledgeBase, task: str, answered: list[str]) -> None:
    """RobotArmServeACup asks for no output; its decomposed plan's goals hold its sub-action
    FindCupOnTable's cupPosition, which is no answer to it."""
    composition = Composer(bundled_kb).compose(REQ + task)
    plan = composition.plan
    assert plan is not None
    outputs = [g for g in plan.goals if g.statement is None and g.source.step is not None]
    assert outputs  # each plan binds an output of a step
    gave = {g.source.step: {g.source.name: {"@type": g.concept}} for g in outputs if g.source.step is not None}
    report = ExecutionReport(task, RunStatus.SUCCEEDED, [StepReport(s.index, s.component) for s in plan.steps])
    report.outputs = gave
    assert [a.name for a in RunResult(composition, report).answers] == answered


def test_a_goal_the_world_cannot_check_is_said_so_not_passed_over(lab_kb: KnowledgeBase) -> None:
    """A lab's goal (a person informed of a weight) has no test in the environment: ``holds`` is None. The
    verdict said "succeeded" as for a goal the world confirmed, with no word that nothing checked it."""
    result = _run(lab_kb, Answering())
    told = Statement(HOME + "Person", "https://example.org/lab#isInformedOf", HOME + "ObjectWeight")
    near = Statement(HOME + "MobileRobot", HOME + "isNear", HOME + "Person")
    verdict = run_text(replace(result, goals=(GoalCheck(near, True, True), GoalCheck(told, True, None))), 0.0, 0.0)
    assert "succeeded; 1 goal(s) confirmed in the world; 1 goal(s) the world cannot check" in verdict
    assert "(home:Person, https://example.org/lab#isInformedOf, home:ObjectWeight): the robots believe it" in verdict
    unknown = run_text(replace(result, goals=(GoalCheck(told, None, None),)), 0.0, 0.0)
    assert "cannot check ((home:Person, https://example.org/lab#isInformedOf, home:ObjectWeight): nothing" in unknown
    assert "cannot check" not in run_text(replace(result, goals=(GoalCheck(near, True, True),)), 0.0, 0.0)
    refuted = run_text(replace(result, goals=(GoalCheck(near, True, False), GoalCheck(told, None, None))), 0.0, 0.0)
    assert "does not hold" in refuted and "cannot check" not in refuted  # a refuted run says only that
