"""``cbrs run``'s text says how the task's own preconditions stood before its first step, as its JSON's
``preconditions`` does: in one line, those perceived holding counted and those no test decides (taken as
given) named, at most three (docs/execution.md, "A task's preconditions"). With the stand-in home of
tests/test_task_preconditions.py (no simulator)."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

from cbrs.actions.graph import statement_text
from cbrs.actions.runner import RunResult, run_task
from cbrs.actions.task_preconditions import PreconditionCheck
from cbrs.cli_actions import run_text
from cbrs.kb import KnowledgeBase, Statement
from cbrs.kb.resources import ontology_dir
from cbrs.tasks import PRECONDITIONS_NAMED
from tests.test_task_preconditions import EX, ON_TRAY, TASK, Home


@pytest.fixture(scope="module")
def given_kb(tmp_path_factory: pytest.TempPathFactory) -> KnowledgeBase:
    store = KnowledgeBase.open(":memory:")
    store.load([ontology_dir() / "core.ttl"], graph="ontology")
    path: Path = tmp_path_factory.mktemp("given") / "given.ttl"
    path.write_text(TASK, encoding="utf-8")
    store.load([path])
    return store


def _lines(result: RunResult) -> list[str]:
    return [line for line in run_text(result, 0.0, 0.0).splitlines() if line.startswith("preconditions")]


def test_a_precondition_no_test_decides_is_named_as_taken_as_given(given_kb: KnowledgeBase) -> None:
    result = run_task(given_kb, EX + "Req", Home(None))
    assert result.succeeded
    assert _lines(result) == [f"preconditions: 1 taken as given, no test decides it: {statement_text(ON_TRAY)}"]
    text = run_text(result, 0.0, 0.0).splitlines()
    assert text.index(_lines(result)[0]) == text.index(next(line for line in text if "succeeded;" in line)) + 1


def test_a_precondition_perceived_holding_is_counted_not_named(given_kb: KnowledgeBase) -> None:
    result = run_task(given_kb, EX + "Req", Home(True))
    assert _lines(result) == ["preconditions: 1 perceived holding"]


def test_many_taken_as_given_are_named_up_to_a_bound_in_one_line(given_kb: KnowledgeBase) -> None:
    result = run_task(given_kb, EX + "Req", Home(True))
    given = [Statement(EX + f"Thing{n}", EX + "on", EX + "Tray") for n in range(PRECONDITIONS_NAMED + 2)]
    checks = (PreconditionCheck(ON_TRAY, True), *(PreconditionCheck(s, None) for s in given))
    (line,) = _lines(dataclasses.replace(result, preconditions=checks))
    named = "; ".join(statement_text(s) for s in given[:PRECONDITIONS_NAMED])
    assert line == (
        f"preconditions: 1 perceived holding; {len(given)} taken as given, no test decides them: {named}; "
        "and 2 more (--json lists each)"
    )
    assert statement_text(given[-1]) not in line


def test_a_task_without_preconditions_has_no_line(given_kb: KnowledgeBase) -> None:
    result = dataclasses.replace(run_task(given_kb, EX + "Req", Home(None)), preconditions=())
    assert _lines(result) == []
